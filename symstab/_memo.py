"""Caches of methods: per object, or shared by the objects of one definition.

``functools.lru_cache`` on a method keys a module-wide cache on ``self``:
every object ever asked stays alive as long as the cache (for a
:class:`symstab.Loop`, its SymPy expressions and kernels).  Here each object
holds its own bounded cache, and a loop that goes out of use takes its cache
with it (:func:`method_cache`).

What depends only on an object's definition (a loop's plant and environment:
its derivation, its pulse transfer function at numbers) is the same for
every object built from it, and costs seconds of SymPy each time.  An object
may therefore name a *shared store* in its attribute ``shared_memo`` (a dict that
the objects of one definition share; :class:`SharedStores` hands them out,
the least recently used dropped first) and keep such values there:
:func:`method_cache` with ``shared=True`` and :class:`shared_property`.
"""

import collections
import functools


def method_cache(maxsize=None, *, shared=False):
    """Cache a method's results per object, on hashable arguments, the oldest dropped first.

    Parameters
    ----------
    maxsize : int, optional
        Results kept per object (``None``: all of them).
    shared : bool, optional
        Keep them in the object's shared store ``self.shared_memo`` (see the
        module's docstring) instead of the object: for a method whose
        result depends only on what defines the store.

    Returns
    -------
    callable
        A decorator for methods whose positional arguments are hashable.
    """
    def decorate(method):
        slot = f"_method_cache_{method.__name__}"

        @functools.wraps(method)
        def cached(self, *args):
            home = self.shared_memo if shared else self.__dict__
            store = home.get(slot)
            if store is None:
                store = home[slot] = collections.OrderedDict()
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


class shared_property:
    """``functools.cached_property`` kept in the object's shared store ``self.shared_memo``.

    For a property that depends only on what defines the store: computed
    once for all the objects that share it.
    """

    def __init__(self, func):
        self.func = func
        self.__doc__ = func.__doc__
        self.name = func.__name__

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        store = obj.shared_memo
        try:
            return store[self.name]
        except KeyError:
            value = store[self.name] = self.func(obj)
            return value


class SharedStores:
    """The shared stores of one kind of object, one per definition, the ``size`` last used kept.

    Parameters
    ----------
    size : int
        Definitions whose store is kept; an older one is dropped (its objects
        keep using it, a new object of that definition starts afresh).
    """

    def __init__(self, size):
        self.size = size
        self._stores = collections.OrderedDict()

    def __call__(self, key):
        """The store (a dict) of the definition ``key`` (hashable)."""
        store = self._stores.get(key)
        if store is None:
            store = self._stores[key] = {}
            if len(self._stores) > self.size:
                self._stores.popitem(last=False)
        else:
            try:
                self._stores.move_to_end(key)
            except KeyError:  # dropped by another thread meanwhile: still a valid store
                pass
        return store

    def clear(self):
        """Forget every store: the next object of each definition computes afresh."""
        self._stores.clear()
