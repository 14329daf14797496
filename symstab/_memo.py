"""A method's cache that lives and dies with its object.

``functools.lru_cache`` on a method keys a module-wide cache on ``self``:
every object ever asked stays alive as long as the cache (for a
:class:`symstab.Loop`, its SymPy expressions and kernels).  Here each object
holds its own bounded cache, and a loop that goes out of use takes its cache
with it.
"""

import collections
import functools


def method_cache(maxsize=None):
    """Cache a method's results per object, on hashable arguments, the oldest dropped first.

    Parameters
    ----------
    maxsize : int, optional
        Results kept per object (``None``: all of them).

    Returns
    -------
    callable
        A decorator for methods whose positional arguments are hashable.
    """
    def decorate(method):
        slot = f"_method_cache_{method.__name__}"

        @functools.wraps(method)
        def cached(self, *args):
            store = self.__dict__.get(slot)
            if store is None:
                store = self.__dict__[slot] = collections.OrderedDict()
            if args in store:
                store.move_to_end(args)
                return store[args]
            value = method(self, *args)
            store[args] = value
            if maxsize is not None and len(store) > maxsize:
                store.popitem(last=False)
            return value

        return cached

    return decorate
