"""Output files are written whole or not at all: write to a temporary file beside the target, then rename.

- :func:`atomic_write` writes one file so: the target appears complete or not at all.
- :func:`check_output_path` checks, before any work starts, that a file can be written where the user
  asked (not a folder, its folder exists, a file can be created there).
- :class:`OutputSet` holds the outputs of one command: each is staged as a hidden temporary file beside
  its target (``.NAME.XXXXXXXX.part``), written there, and all are renamed onto their targets together
  by :meth:`OutputSet.commit` once every one is complete; on any exception before that
  (``KeyboardInterrupt`` included) the temporary files are removed and the targets stay as they were.
"""

from __future__ import annotations

import contextlib
import os
import signal
import stat
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

#: the temporary files of :func:`atomic_write` and :class:`OutputSet`: ``.{target name}.{random}.part``
TEMPORARY_SUFFIX = ".part"


def _temporary_beside(target: Path) -> str:
    """Create an empty hidden temporary file in *target*'s folder and return its path."""
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=TEMPORARY_SUFFIX, dir=_folder(target))
    os.close(fd)
    return tmp


def _folder(target: Path) -> Path:
    return target.parent if str(target.parent) else Path(".")


def _ordinary_permissions(path: str) -> None:
    """mkstemp creates 0600; give the file the permissions an ordinary ``open()`` would."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(path, 0o666 & ~umask)


def _remove(path: str) -> None:
    try:
        os.remove(path)
    except FileNotFoundError:
        pass


#: the signals a command line turns into exceptions (Ctrl-C, kill); held back while files are renamed or removed
_DEFERRED_SIGNALS = {signal.SIGINT, signal.SIGTERM}


#: the exception a signal raised (``plansim.cli.common.Interrupted``), kept until the command ends: raised inside a
#: garbage collector's callback or a ``__del__``, Python prints "Exception ignored" and goes on, and the command
#: would run to its end and commit its outputs as if no signal had come (seen once in CI: a SIGTERM during
#: ``plansim run`` swallowed by a WeakValueDictionary callback, the run finished with exit status 0)
_PENDING: list[BaseException] = []


def note_signal(exc: BaseException) -> None:
    """Remember the exception a signal raised, so that :func:`raise_pending_signal` raises it again."""
    _PENDING.append(exc)


def forget_signals() -> None:
    """Forget the signals remembered (a command starts or has ended)."""
    _PENDING.clear()


def raise_pending_signal() -> None:
    """Raise again the exception of a signal that came while the command ran (:data:`_PENDING`), if any: what
    :meth:`OutputSet.commit` does before it renames anything."""
    if _PENDING:
        raise _PENDING[0]


@contextlib.contextmanager
def signals_deferred():
    """Hold SIGINT and SIGTERM back in this thread while renaming or removing files, deliver them after.

    So a Ctrl-C cannot land between two renames of :meth:`OutputSet.commit`, nor stop the removal of a
    temporary file half-way. Where threads cannot block signals (not POSIX), nothing is held back.
    """
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, _DEFERRED_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def check_output_path(path: str | os.PathLike, option: str = "output",
                      suffixes: Iterable[str] | None = None) -> Path:
    """Check that a file can be written at *path*, before any work is done; return it as a Path.

    Parameters
    ----------
    path : str or os.PathLike
        The file the user asked for.
    option : str
        How the user named it (``"--out"``, ``"--plot"``); every message starts with it and the path.
    suffixes : iterable of str, optional
        Allowed file name endings (compared without regard to case), e.g. ``(".nc",)``.

    Raises
    ------
    ValueError
        No file name; a suffix not allowed; the path is a folder (or another non-file, such as a
        device); its folder does not exist or is not a folder; a file cannot be created in its folder
        (checked by creating and removing a hidden temporary file there, which is the only check that
        holds for every user, root included, and every file system).
    """
    text = os.fspath(path)
    if not text:
        raise ValueError(f"{option} '': no file name")
    target = Path(text)
    name = f"{option} {text!r}"
    if suffixes is not None:
        suffixes = tuple(suffixes)
        if target.suffix.lower() not in suffixes:
            raise ValueError(f"{name}: the file name must end in {' or '.join(suffixes)}")
    if target.is_dir():
        raise ValueError(f"{name}: is a folder; give the name of a file in it")
    if target.exists() and not stat.S_ISREG(target.stat().st_mode):
        raise ValueError(f"{name}: exists and is not a regular file")
    folder = _folder(target)
    if not folder.exists():
        raise ValueError(f"{name}: the folder {str(folder)!r} does not exist")
    if not folder.is_dir():
        raise ValueError(f"{name}: {str(folder)!r} is not a folder")
    try:
        fd, probe = tempfile.mkstemp(prefix=".plansim-write-check.", dir=folder)
    except OSError as error:
        raise ValueError(f"{name}: cannot write in the folder {str(folder)!r} ({error.strerror})") from None
    os.close(fd)
    _remove(probe)
    return target


def atomic_write(path: str | os.PathLike, writer: Callable[[str], None]) -> None:
    """Call ``writer(tmp_path)`` and move the result onto *path* only if it succeeded.

    The temporary file ``.NAME.XXXXXXXX.part`` sits beside *path*; it is removed on any exception,
    ``KeyboardInterrupt`` included.
    """
    target = Path(path)
    if not _folder(target).exists():
        raise ValueError(f"output {str(target)!r}: the folder {str(_folder(target))!r} does not exist")
    tmp = _temporary_beside(target)
    try:
        writer(tmp)
        with signals_deferred():
            _ordinary_permissions(tmp)
            os.replace(tmp, target)
    except BaseException:
        with signals_deferred():
            _remove(tmp)
        raise


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> None:
    def _write(tmp: str) -> None:
        with open(tmp, "wb") as fh:
            fh.write(data)

    atomic_write(path, _write)


class OutputSet:
    """The output files of one command, committed together or not at all.

    Each output is *staged* (:meth:`stage`, which checks the path first with :func:`check_output_path`):
    an empty hidden temporary file is created beside its target and its path returned, for the writer
    to write as if it were the target. :meth:`commit` renames every staged file onto its target once
    all are complete. Leaving the ``with`` block without a commit, or by any exception
    (``KeyboardInterrupt`` and ``SystemExit`` included), removes the temporary files and leaves every
    target as it was.

    Staging before the work starts also reserves the outputs: a folder that cannot be written is an
    error before, not after, a long simulation.

    Examples
    --------
    >>> with OutputSet() as outputs:                                 # doctest: +SKIP
    ...     results_tmp = outputs.stage("r.nc", "--out", (".nc",))
    ...     figure_tmp = outputs.stage("f.png", "--plot", (".png",))
    ...     write_results(results_tmp); write_figure(figure_tmp)
    ...     outputs.commit()                                        # r.nc and f.png appear together

    Notes
    -----
    The renames run one after another once every file is written; a rename fails only if the folder
    changed under the command (a target turned into a folder, the folder removed). Then the targets
    this commit created are removed again, the remaining temporary files too, and a ValueError names
    the output; a target that existed before and was already replaced keeps its new content.
    """

    def __init__(self) -> None:
        self._staged: list[tuple[Path, str, str]] = []  # (target, temporary file, option)
        self.committed = False

    def stage(self, path: str | os.PathLike, option: str = "output", suffixes: Iterable[str] | None = None) -> str:
        """Check *path* and create the temporary file that stands for it; return that file's path.

        Raises
        ------
        ValueError
            As :func:`check_output_path`; or *path* is already an output of this set.
        """
        if self.committed:
            raise ValueError(f"{option} {os.fspath(path)!r}: this set of outputs is already committed")
        target = check_output_path(path, option, suffixes)
        for other, _, other_option in self._staged:
            if os.path.abspath(other) == os.path.abspath(target):
                raise ValueError(f"{option} {os.fspath(path)!r}: this file is already the output of {other_option}")
        try:
            tmp = _temporary_beside(target)
        except OSError as error:
            raise ValueError(f"{option} {os.fspath(path)!r}: cannot write in the folder "
                             f"{str(_folder(target))!r} ({error.strerror})") from None
        self._staged.append((target, tmp, option))
        return tmp

    @property
    def temporary_files(self) -> list[str]:
        """The staged temporary files, in the order staged."""
        return [tmp for _, tmp, _ in self._staged]

    def commit(self) -> None:
        """Rename every staged file onto its target (with the permissions an ordinary ``open`` gives)."""
        if self.committed:
            return
        raise_pending_signal()  # a signal whose exception was swallowed on the way: nothing is committed
        with signals_deferred():
            self._rename_all()
            self.committed = True

    def _rename_all(self) -> None:
        created: list[Path] = []
        for index, (target, tmp, option) in enumerate(self._staged):
            existed = os.path.lexists(target)
            try:
                _ordinary_permissions(tmp)
                os.replace(tmp, target)
            except OSError as error:
                for path in created:  # undo what this commit created
                    _remove(str(path))
                for _, later, _ in self._staged[index:]:
                    _remove(later)
                self._staged = []
                reason = "is a folder" if target.is_dir() else error.strerror
                raise ValueError(f"{option} {str(target)!r}: could not be written ({reason})") from None
            if not existed:
                created.append(target)

    def discard(self) -> None:
        """Remove every staged temporary file not committed (the targets stay as they were)."""
        if not self.committed:
            with signals_deferred():
                for _, tmp, _ in self._staged:
                    _remove(tmp)
                self._staged = []

    def __enter__(self) -> OutputSet:
        return self

    def __exit__(self, *exc_info) -> None:
        self.discard()
