"""Run the derivation notebooks of the build in one shared kernel.

myst-nb starts a kernel for every notebook it executes, and each kernel
imports symstab and derives the paper's loop again: 9 kernels, about 40 s of
CPU.  Here the build runs them, in the order it reads them, in one
``python3`` kernel started in the notebooks' folder, its namespace reset
(as ``%reset -f`` does) and its figures closed before each notebook, so that a
notebook sees no name another defined (what stays is what a user's session
keeps: the modules imported and what they cached).  The executed notebook
replaces the stored one (which has no outputs) as the page's source;
``nb_execution_mode = "off"`` in conf.py leaves it to this.  A cell that
raises fails the build, naming the notebook.
"""

import pathlib

from sphinx.errors import ExtensionError

#: Run before each notebook in the shared kernel: a clean namespace, no open figure.
#: The namespace reset of ``%reset -f`` without its extra ``gc.collect()`` (the
#: reset already collects once): a full collection of a kernel holding SymPy,
#: NumPy and matplotlib costs a tenth of a second or more, before every notebook.
_RESET = ("get_ipython().reset(new_session=False)\n"
          "import sys as _sys\n"
          "if 'matplotlib.pyplot' in _sys.modules:\n"
          "    _sys.modules['matplotlib.pyplot'].close('all')\n"
          "del _sys")

#: Seconds a cell may take.
TIMEOUT = 600


def _kernel(app, folder):
    """The build's kernel (started on first use, in ``folder``)."""
    manager = getattr(app, "_shared_kernel", None)
    if manager is None or not manager.is_alive():
        from jupyter_client.manager import KernelManager

        manager = KernelManager(kernel_name="python3")
        manager.start_kernel(cwd=str(folder))
        app._shared_kernel = manager
    return manager


def _execute(nb, manager, folder):
    """Execute ``nb`` top to bottom in ``manager``'s kernel; close the client's channels."""
    import nbclient

    client = nbclient.NotebookClient(nb, km=manager, timeout=TIMEOUT, kernel_name="python3",
                                     resources={"metadata": {"path": str(folder)}})
    try:
        client.execute()
    finally:
        if client.kc is not None:
            client.kc.stop_channels()


def _source_read(app, docname, source):
    """The notebook ``docname``, executed in the shared kernel, as its page's source."""
    path = pathlib.Path(app.env.doc2path(docname))
    if path.suffix != ".ipynb":
        return
    import nbclient
    import nbformat

    folder = path.resolve().parent
    manager = _kernel(app, folder)
    _execute(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(_RESET)]), manager, folder)
    nb = nbformat.reads(source[0], as_version=4)
    try:
        _execute(nb, manager, folder)
    except nbclient.exceptions.CellExecutionError as exc:
        raise ExtensionError(f"{path.name}: a cell raised\n{exc}") from None
    source[0] = nbformat.writes(nb)


def _shutdown(app, exception):
    manager = getattr(app, "_shared_kernel", None)
    if manager is not None:
        manager.shutdown_kernel(now=True)


def setup(app):
    app.connect("source-read", _source_read)
    app.connect("build-finished", _shutdown)
    return {"parallel_read_safe": False, "parallel_write_safe": True}
