"""numpydoc's docstring template, compiled once per builder instead of once per docstring.

numpydoc 1.11's ``docscrape_sphinx.get_doc_object`` (the newest release) makes a
new jinja2 environment and compiles its ``numpydoc_docstring.rst`` template for
every docstring it renders and every signature it reads: about 1 800 compiles,
several seconds of a build.  The template depends only on the builder (its
loader looks in the builder's template folders), so here it is made the same way
once per builder and handed to numpydoc's own ``docscrape.get_doc_object`` with
numpydoc's Sphinx classes, as ``docscrape_sphinx.get_doc_object`` does.
numpydoc's ``setup`` takes such a replacement (its ``get_doc_object_``
argument); it is installed the same way, in numpydoc's module.  Should a numpydoc
release change ``get_doc_object``'s signature, numpydoc's own is left in place.
"""

import inspect
import os

_SIGNATURE = ["obj", "what", "doc", "config", "builder"]
#: The template made without a builder (numpydoc's signature reading), once.
_NO_BUILDER = {}


def _template(builder):
    """numpydoc's template as its ``get_doc_object`` makes it for ``builder`` (cached)."""
    from jinja2 import FileSystemLoader
    from jinja2.sandbox import SandboxedEnvironment
    from numpydoc import docscrape_sphinx
    from sphinx.jinja2glue import BuiltinTemplateLoader

    cache = _NO_BUILDER if builder is None else builder.__dict__
    if "_numpydoc_template" not in cache:
        dirs = [os.path.join(os.path.dirname(docscrape_sphinx.__file__), "templates")]
        if builder is not None:
            loader = BuiltinTemplateLoader()
            loader.init(builder, dirs=dirs)
        else:
            loader = FileSystemLoader(dirs)
        environment = SandboxedEnvironment(loader=loader)
        cache["_numpydoc_template"] = environment.get_template("numpydoc_docstring.rst")
    return cache["_numpydoc_template"]


def get_doc_object(obj, what=None, doc=None, config=None, builder=None):
    """numpydoc's ``docscrape_sphinx.get_doc_object``, with the builder's template made once."""
    from numpydoc import docscrape, docscrape_sphinx

    config = {} if config is None else config
    config["template"] = _template(builder)
    return docscrape.get_doc_object(obj, what=what, doc=doc, config=config,
                                    class_doc=docscrape_sphinx.SphinxClassDoc,
                                    func_doc=docscrape_sphinx.SphinxFunctionDoc,
                                    obj_doc=docscrape_sphinx.SphinxObjDoc)


def setup(app):
    app.setup_extension("numpydoc")
    from numpydoc import docscrape_sphinx
    from numpydoc import numpydoc as extension

    if list(inspect.signature(docscrape_sphinx.get_doc_object).parameters) == _SIGNATURE:
        extension.get_doc_object = get_doc_object
    return {"parallel_read_safe": True, "parallel_write_safe": True}
