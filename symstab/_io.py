"""Files written whole or not at all: the package's one atomic writer."""

import os
import pathlib
import tempfile


def write_bytes(path, data):
    """Write ``data`` (bytes) to ``path`` atomically.

    The bytes go to a temporary name in the same folder, which is renamed
    into place, so a failure never leaves a half-written file.  A link is
    followed (its target is replaced, not the link), and a path that exists
    but is not a regular file (a device such as ``/dev/null``, a pipe) is
    refused: the rename would replace it.
    """
    path = pathlib.Path(os.path.realpath(path))
    if path.exists() and not path.is_file():
        raise OSError(f"{path} exists and is not a regular file (a device, a pipe or a folder)")
    folder = path.parent
    folder.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        pathlib.Path(tmp).unlink(missing_ok=True)
        raise
    return path
