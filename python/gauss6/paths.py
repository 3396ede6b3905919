"""Where gauss6 finds its own files: the repository, the CMake build tree and its tools, the datasets.

In a checkout the package is python/gauss6 (tools/setup.sh puts python/ on the venv's path), so
the repository root is two levels above this file; GAUSS6_BUILD_DIR overrides the build tree
(default build/). An installed wheel has no checkout: its programs are in the package's bin/
(tool()), and the datasets folder is GAUSS6_DATASETS_DIR, else ./datasets_generated.
"""
from __future__ import annotations

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]
# Whether this package is a checkout's python/gauss6 (not an installed copy).
IN_CHECKOUT = (REPO_ROOT / "python" / "gauss6" / "paths.py").resolve() == Path(__file__).resolve()
_PACKAGE_BIN = Path(__file__).resolve().parent / "bin"  # the programs a wheel carries


def build_dir() -> Path:
    """The CMake build tree (GAUSS6_BUILD_DIR, default <repo>/build)."""
    return Path(os.environ.get("GAUSS6_BUILD_DIR", REPO_ROOT / "build"))


def tool(relpath: str) -> Path:
    """A program built by CMake, e.g. tool("datasets_generated/gauss6_make_bunny"): in the build
    tree, else (an installed wheel) the package's bin/ copy.

    Raises FileNotFoundError naming the missing program and how to build it.
    """
    path = build_dir() / relpath
    if not path.exists() and (_PACKAGE_BIN / Path(relpath).name).exists():
        return _PACKAGE_BIN / Path(relpath).name
    if not path.exists():
        raise FileNotFoundError(f"{path}: not built; run `make test` or `cmake --build {build_dir()}`")
    return path


# The datasets: GAUSS6_DATASETS_DIR, else the checkout's datasets_generated/, else (an installed
# package) ./datasets_generated, where `gauss6 datasets generate` writes them.
DATASETS_DIR = Path(os.environ.get("GAUSS6_DATASETS_DIR") or (REPO_ROOT / "datasets_generated" if IN_CHECKOUT
                                                                else Path.cwd() / "datasets_generated"))
SHARED_DATA_DIR = REPO_ROOT.parent / "shared" / "data"


# ---------------------------------------------------------------------------------------------
# Paths given by the user: what they are is checked before anything is read or written, so that
# a FIFO, a device (/dev/zero), a directory or a file too large for its format is refused with
# a message naming the path, never read until memory runs out or a hang.

class PathError(ValueError):
    """A path that cannot serve as asked (not a regular file, too large, not writable): the
    message names the path and the problem. A ValueError, as gauss6.LoadError is."""


def _kind(mode: int) -> str:
    import stat

    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISSOCK, "a socket"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device")):
        if test(mode):
            return name
    return "not a regular file"


def check_input_file(path, what: str = "file", max_bytes: int | None = None) -> Path:
    """path, when it is a regular file (symbolic links followed) of at most max_bytes bytes;
    else PathError naming what it is ("a FIFO", "a directory", ...). Nothing is opened."""
    import stat

    path = Path(path)
    try:
        st = path.stat()
    except OSError as e:
        raise PathError(f"{path}: cannot open the {what}: {e.strerror or e}") from None
    if not stat.S_ISREG(st.st_mode):
        raise PathError(f"{path}: the {what} is {_kind(st.st_mode)}, not a regular file")
    if max_bytes is not None and st.st_size > max_bytes:
        raise PathError(f"{path}: the {what} has {st.st_size} bytes, more than a {what} can hold "
                        f"({max_bytes} bytes)")
    return path


def read_input_bytes(path, what: str = "file", max_bytes: int | None = None) -> bytes:
    """The bytes of a checked input file (check_input_file), never more than max_bytes read
    even if the file grows meanwhile."""
    path = check_input_file(path, what, max_bytes)
    try:
        with open(path, "rb") as f:
            data = f.read() if max_bytes is None else f.read(max_bytes + 1)
    except OSError as e:
        raise PathError(f"{path}: cannot read the {what}: {e.strerror or e}") from None
    if max_bytes is not None and len(data) > max_bytes:
        raise PathError(f"{path}: the {what} has more than {max_bytes} bytes, more than a {what} can hold")
    return data


def read_input_text(path, what: str = "file", max_bytes: int | None = None) -> str:
    """read_input_bytes decoded as UTF-8 (PathError naming the byte offset when it is not)."""
    data = read_input_bytes(path, what, max_bytes)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise PathError(f"{path}: the {what} is not UTF-8 text (byte {e.start})") from None


def read_input_lines(path, what: str, max_line: int) -> list[str]:
    """The lines of a checked text file, each read with at most max_line + 1 bytes in memory:
    a longer line (a format's row cannot be that long) is refused by its number before the
    rest of it is read."""
    path = check_input_file(path, what)
    lines = []
    try:
        with open(path, "rb") as f:
            while True:
                raw = f.readline(max_line + 1)
                if not raw:
                    break
                if len(raw) > max_line and not raw.endswith(b"\n"):
                    raise PathError(f"{path}:{len(lines) + 1}: line longer than {max_line} bytes, more than "
                                    f"a {what} row can hold")
                try:
                    lines.append(raw.decode("utf-8").rstrip("\r\n"))
                except UnicodeDecodeError as e:
                    raise PathError(f"{path}:{len(lines) + 1}: the {what} is not UTF-8 text "
                                    f"(byte {e.start} of the line)") from None
    except OSError as e:
        raise PathError(f"{path}: cannot read the {what}: {e.strerror or e}") from None
    return lines


def output_problem(path, want_dir: bool, what: str) -> str:
    """'' when path can be written as a directory (want_dir) or a file, else the problem: an
    existing file where a directory is wanted or the reverse, something that is neither, a
    path under a file, a folder without write permission. Nothing is created."""
    path = Path(path)
    if path.exists():
        if want_dir and not path.is_dir():
            return f"{path}: the {what} exists and is not a directory"
        if not want_dir and path.is_dir():
            return f"{path}: the {what} is an existing directory; give a file path"
        if not want_dir and not path.is_file():
            return f"{path}: the {what} exists and is not a regular file"
    parent = path if want_dir else path.parent
    while not parent.exists() and parent != parent.parent:  # the nearest folder that exists
        parent = parent.parent
    if parent.exists() and not parent.is_dir():
        return f"{path}: cannot create the {what}: {parent} is not a directory"
    if not os.access(parent, os.W_OK | os.X_OK) or (path.exists() and not os.access(path, os.W_OK)):
        return f"{path}: the {what} is not writable (permission denied)"
    return ""


def check_output_file(path, what: str = "output file") -> Path:
    """path can be written as a file (output_problem), its folder created; PathError otherwise."""
    problem = output_problem(path, False, what)
    if problem:
        raise PathError(problem)
    check_output_dir(Path(path).parent, f"folder of the {what}")
    return Path(path)


def check_output_dir(path, what: str = "output directory") -> Path:
    """path is a writable directory (output_problem), created with its parents when missing;
    PathError naming the problem otherwise."""
    problem = output_problem(path, True, what)
    if problem:
        raise PathError(problem)
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise PathError(f"{path}: cannot create the {what}: {e.strerror or e}") from None
    return path
