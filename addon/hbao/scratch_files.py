# SPDX-License-Identifier: GPL-2.0-or-later
"""Where the hand-over's scratch files go (handover.py saves the Render
Result there and reads it back) and how they are removed: in the
background, after the AO; those of Blenders that have ended, at the first
hand-over. bpy-free; their names are scratch_names.py's."""
import contextlib
import hashlib
import itertools
import os
import tempfile
import threading
import time

from . import scratch_names
from .report import log

# Environment variable naming the folder for the scratch EXR instead of the
# default; several, separated by os.pathsep (':'), are tried in turn.
SCRATCH_FOLDER_VARIABLE = "HBAO_TEMP_DIR"
# Memory-backed where there is one: the file lives for milliseconds.
MEMORY_FOLDER = "/dev/shm"


# Folders that failed to take a scratch file in this process: tried last.
_failed = []


def folders():
    """The folders to save the scratch file in, in the order to try them:
    HBAO_TEMP_DIR's; by default the memory-backed folder, then the system's
    temporary folder, for a Render Result that does not fit in memory (a
    container's /dev/shm is 64 MB by default, less than a 1080p render's
    Combined, Depth and Normal). A folder that failed (failed()) comes
    last, so later hand-overs do not fill it again first."""
    configured = os.environ.get(SCRATCH_FOLDER_VARIABLE, "")
    # "//tmp" ("$ROOT/tmp" with ROOT=/) is /tmp on POSIX, which Blender's
    # save took for a path relative to the .blend file, with a warning every
    # frame (Windows' "\\server\share" is no such case)
    listed = [("/" + folder.lstrip("/")) if os.name == "posix" and folder.startswith("/")
              else folder for folder in configured.split(os.pathsep) if folder]
    if not listed:
        memory = [MEMORY_FOLDER] if os.path.isdir(MEMORY_FOLDER) and \
            os.access(MEMORY_FOLDER, os.W_OK) else []
        listed = memory + [tempfile.gettempdir()]
    return sorted(listed, key=lambda folder: folder in _failed)  # (a stable sort)


def failed(folder, paths):
    """`folder` could not take a scratch file: tried last from now on, and
    its `paths` removed at once (in the background), not after the AO, so
    that a full folder is free again for other programs."""
    if folder not in _failed:
        _failed.append(folder)
    _in_background(_remove_all, list(paths))


# Each scratch file its own number: the last one may still be being removed
# (remove_later) when the next is saved.
_scratch_numbers = itertools.count()


def _read_text(path):
    try:
        with open(path, encoding="ascii", errors="replace") as file:
            return file.read().strip()
    except OSError:
        return ""


def process_space():
    """8 hex digits naming where this process's id means something: the
    machine's boot (Linux's boot_id) and its PID namespace (the inode of
    /proc/self/ns/pid). Two Blenders of one space see each other's process
    ids; of two spaces, not (another machine, another container). Where
    either cannot be read (no /proc, another system), the space is the
    process's own, random: every other process's files are then another
    space's, removed only when an hour old (a host name alone, or a
    namespace taken for the same, let one container remove another's file
    in use: a review)."""
    boot = _read_text("/proc/sys/kernel/random/boot_id")
    try:
        namespace = os.stat("/proc/self/ns/pid").st_ino
    except OSError:
        namespace = None
    if not boot or namespace is None:
        return os.urandom(4).hex()
    return hashlib.sha256(f"{boot}/{namespace}".encode()).hexdigest()[:8]


# This process's: its space, and a random run (scratch_names.py).
_space = process_space()
_run = os.urandom(4).hex()


def path_in(folder):
    """A new scratch file's path in `folder`."""
    return os.path.join(folder, scratch_names.name(
        os.getpid(), threading.get_ident(), next(_scratch_numbers), _space, _run))


def _process_ended(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except (OSError, OverflowError):  # another user's (alive), or no process id at all
        return False
    return False


# How often a process looks for stale scratch files (remove_stale_now_and_then).
STALE_CHECK_INTERVAL_S = 600
# How old a file named before session 33 (no space) must be to be stale.
UNPLACED_STALE_AGE_S = 600
# How old a file of another space (scratch_names.py) must be to be stale: its
# process cannot be asked about from here, and the clocks of the machines
# that share a folder may differ (a file server's clock sets its time). A
# scratch file lives for a second or so; an hour covers any clock a farm
# keeps in step.
OTHER_SPACE_STALE_AGE_S = 3600


def _stale(owner, age_s):
    """Whether a scratch file of `owner` (scratch_names.Owner), `age_s`
    old by this machine's clock, is left over: this space's, of a process
    that has ended (this process's id with another run: one that ended
    before this process got its id); another space's, an hour old; one
    named before session 33, of an ended process and UNPLACED_STALE_AGE_S old."""
    if owner.space == _space:
        if owner.process == os.getpid():
            return owner.run != _run
        return _process_ended(owner.process)
    if owner.space is not None:
        return age_s >= OTHER_SPACE_STALE_AGE_S
    return age_s >= UNPLACED_STALE_AGE_S and _process_ended(owner.process)


def remove_stale_scratch_files():
    """Remove the scratch files of Blender processes that have ended: one
    killed while it handed passes over, or a bpy script that ended by
    os._exit before its removal thread was done (_stale says which). A
    file of a running process, or one this user may not remove, is left
    alone. Returns the paths removed."""
    removed = []
    for folder in folders():
        try:
            names = os.listdir(folder)
        except OSError:
            continue
        now = time.time()
        for name in names:
            owner = scratch_names.owner_of(name)
            if owner is None:
                continue
            path = os.path.join(folder, name)
            try:
                if not _stale(owner, now - os.stat(path).st_mtime):
                    continue
                os.remove(path)
                removed.append(path)
            except OSError:
                pass
    return removed


_stale_files_checked_at = None  # time.monotonic() of the last look


def remove_stale_now_and_then():
    """At a process's first hand-over, and again at the first after
    STALE_CHECK_INTERVAL_S more: remove_stale_scratch_files() in the
    background (a hand-over need not wait for it). A long animation started
    just after a Blender was killed removes that Blender's file once it is
    stale (an 8K frame's is about a gigabyte of /dev/shm), not only the next
    Blender to start."""
    global _stale_files_checked_at
    now = time.monotonic()
    last = _stale_files_checked_at
    if last is None or now - last >= STALE_CHECK_INTERVAL_S:
        _stale_files_checked_at = now
        _in_background(_remove_stale_files)


def _remove(path):
    if not os.path.lexists(path):  # (a read-only folder says EROFS for it)
        return
    try:
        os.remove(path)
    except FileNotFoundError:
        pass
    except OSError as error:
        log(f"could not remove the scratch file {path}: {error}")


# The removals started and not yet waited for.
_removals = []
_removals_lock = threading.Lock()


def _in_background(removal, *args):
    """removal(*args) in a thread of its own, counted among the removals
    that the next save waits for. Freeing a large file's pages is the
    kernel's work, and long: a 1920x1080 render with 81 channels, 672 MB,
    took 115 ms on tmpfs (docs/speed.md, session 19), which the render need
    not wait for (nor the AO share the cores with: removals_after). Not a
    daemon thread: Python waits for it before the process ends, so no
    scratch file outlives Blender (a process that ends by os._exit skips
    that wait: scripts/bpy_blender.py waits first). Where no thread can be
    started (the process has run out of them), it runs at once, and the
    render waits for it."""
    thread = threading.Thread(target=removal, args=args, name="hbao-scratch-removal")
    try:
        thread.start()
    except RuntimeError as error:
        log(f"removing scratch files in the render's own thread: {error}")
        removal(*args)
        return
    with _removals_lock:
        _removals.append(thread)


# The scratch files whose removal waits for the end of a removals_after()
# block of this thread; None outside one.
_deferred = threading.local()


def remove_later(path):
    """Remove `path` in the background (_in_background), or at the end of
    the removals_after() block this thread is in."""
    waiting = getattr(_deferred, "paths", None)
    if waiting is not None:
        waiting.append(path)
    else:
        _in_background(_remove, path)


@contextlib.contextmanager
def removals_after():
    """Within the block, the hand-over's scratch files are removed only when
    it ends (however it ends), all of them by one removal in the background.
    The engine computes the AO in such a block: the removal's kernel work
    then runs beside what Blender does after the AO, not beside the AO's
    threads, which keep every core busy (docs/speed.md, session 23). A
    block within a block of the same thread leaves its files to the outer
    one; other threads' removals are not held back."""
    outer = getattr(_deferred, "paths", None)
    _deferred.paths = [] if outer is None else outer
    try:
        yield
    finally:
        if outer is None:
            waiting, _deferred.paths = _deferred.paths, None
            if waiting:
                _in_background(_remove_all, waiting)


def _remove_all(paths):
    for path in paths:
        _remove(path)


def _remove_stale_files():
    for stale in remove_stale_scratch_files():
        log(f"removed {stale}, left by a Blender that has ended")


def wait_for_older_removals():
    """Before the next save: every removal but the latest done, so that
    besides the files being saved and read, only the latest removal's may
    still exist (a frame's, up to three with a guard band and back faces:
    removals_after), however quickly frames follow each other; a frame's
    second save (a guard band's, a back face layer's) does not wait for the
    removal before it."""
    with _removals_lock:
        older = _removals[:-1]
        del _removals[:-1]
    for thread in older:
        thread.join()
