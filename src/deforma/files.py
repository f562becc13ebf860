"""Output files that appear whole or not at all.

Every output (a video, a PNG, a states file, a sweep's table part) is written to a temporary
file beside its target and renamed into place only when it is complete (:func:`write_atomic`,
or :func:`temp_beside` and :func:`publish` for writers that hand the path to another program),
so an interrupted run (Ctrl-C, a crash, an unstable simulation) never leaves a broken file:
either the old one or a complete one.

Temporary names carry the writing process's id (``.NAME.PID.RANDOM.partial.SUFFIX``). A run
killed outright (SIGKILL, a power cut) cannot clean up, so the next run that writes into the
same folder removes the temporary files whose process no longer exists and that were last
written before it started (see :func:`remove_stale_partials`). A process id taken again by
another program keeps its file until that id is free.

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> target = Path(tempfile.mkdtemp()) / "note.txt"
>>> write_atomic(target, lambda f: f.write(b"whole or not at all"))
>>> target.read_text()
'whole or not at all'
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import tempfile
import time
from pathlib import Path
from typing import BinaryIO, Callable

__all__ = ["check_folder", "failed_write", "publish", "remove_stale_partials", "temp_beside", "temp_folder_in", "write_atomic"]


def check_folder(path, folder: Path) -> None:
    """Check that ``folder``, where ``path`` will be written, exists and is writable.

    Raises
    ------
    ValueError
        One line naming ``path`` and the folder.
    """
    if not folder.is_dir():
        raise ValueError(f"{path}: the folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"{path}: the folder {str(folder)!r} is not writable")


def temp_beside(target: Path) -> Path:
    """A fresh hidden file next to ``target`` with the same suffix (ffmpeg picks formats by it).

    Its name carries this process's id, so a later run can tell it is stale; the first call per
    folder removes the stale ones of earlier, killed runs (:func:`remove_stale_partials`).
    """
    target = Path(target)
    _sweep_once(target.parent)
    fd, name = tempfile.mkstemp(prefix=f".{target.stem}.{os.getpid()}.", suffix=f".partial{target.suffix}",
                                dir=target.parent)
    os.close(fd)
    return Path(name)


def temp_folder_in(folder: Path) -> Path:
    """A fresh hidden folder inside ``folder``, named like :func:`temp_beside`'s files."""
    _sweep_once(folder)
    return Path(tempfile.mkdtemp(prefix=f".frames.{os.getpid()}.", suffix=".partial", dir=folder))


# .NAME.PID.RANDOM.partial[.SUFFIX]: RANDOM is mkstemp's 8 characters
_PARTIAL_NAME = re.compile(r"^\..*\.(?P<pid>\d+)\.[A-Za-z0-9_]{8}\.partial(\.[A-Za-z0-9]+)?$")
_swept: set[str] = set()
_STARTED = time.time()  # about when this process began: later files belong to runs going on now


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError, OSError):
        return True  # someone else's live process (or an id we cannot ask about): keep its file
    return True


def remove_stale_partials(folder, *, before: float | None = None) -> list[Path]:
    """Remove the temporary outputs in ``folder`` left by runs that were killed; returns them.

    A temporary file or folder (``.NAME.PID.RANDOM.partial[.SUFFIX]``) is stale when no process
    of that id exists and it was last written before ``before`` (a time stamp; default: when
    this process started). The time test keeps the files of a run on another machine that
    writes into a shared folder now. Errors (a file removed meanwhile, no permission) are
    ignored: cleaning up is a courtesy, never a reason to fail a run.
    """
    before = _STARTED if before is None else before
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for e in entries:
        m = _PARTIAL_NAME.match(e.name)
        if m is None or _pid_alive(int(m.group("pid"))):
            continue
        try:
            if e.stat(follow_symlinks=False).st_mtime >= before:
                continue
            if e.is_dir(follow_symlinks=False):
                shutil.rmtree(e.path)
            else:
                os.unlink(e.path)
            removed.append(Path(e.path))
        except OSError:
            pass
    return removed


def _sweep_once(folder) -> None:
    key = os.path.abspath(folder)
    if key not in _swept:
        _swept.add(key)
        remove_stale_partials(folder)


def publish(tmp, target) -> None:
    """Give a finished temporary file normal permissions and rename it onto ``target`` atomically.

    ``mkstemp`` makes private (0600) files; the output should get what any new file gets (0666
    minus the umask).
    """
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(tmp, 0o666 & ~mask)
    os.replace(tmp, target)


def write_atomic(path, write: Callable[[BinaryIO], object]) -> None:
    """Call ``write(file)`` on a temporary file beside ``path`` (opened for binary writing), then
    rename it into place; on any failure, Ctrl-C included, the temporary file is removed and
    ``path`` is left as it was.

    Parameters
    ----------
    path : str or Path
        The file to write; its folder must exist.
    write : callable
        Writes the whole content to the open file it is given.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> target = Path(tempfile.mkdtemp()) / "data.bin"
    >>> write_atomic(target, lambda f: f.write(bytes(3)))
    >>> target.read_bytes()
    b'\\x00\\x00\\x00'
    """
    path = Path(path)
    tmp = temp_beside(path)
    try:
        with open(tmp, "wb") as f:
            write(f)
        publish(tmp, path)
    except OSError as e:
        tmp.unlink(missing_ok=True)
        raise failed_write(path, e) from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def failed_write(path, error: OSError) -> OSError:
    """A one-line error for a file that could not be written, naming it (an OSError such as a
    full disk's ``[Errno 28]`` names only the temporary file, or nothing); ``errno`` is kept.

    Examples
    --------
    >>> import errno
    >>> str(failed_write("out/s.npz", OSError(errno.ENOSPC, "No space left on device")))
    'out/s.npz: could not be written: no space left on the device; nothing was written'
    """
    if getattr(error, "errno", None) in (errno.ENOSPC, errno.EDQUOT):
        why = "no space left on the device"
    else:
        why = (error.strerror or str(error) or type(error).__name__).strip().splitlines()[0]
    out = OSError(f"{path}: could not be written: {why}; nothing was written")
    out.errno = getattr(error, "errno", None)
    return out
