# SPDX-License-Identifier: GPL-2.0-or-later
"""Run in every Blender of the matrix by tests/test_addon.py: the hand-over
removes its scratch files in threads of their own (scratch_files.remove_later),
and before each save waits for every removal but the latest, so that at most
two scratch files exist at a time. Here the removals are held back until
released, to see who waits for whom; where no thread can be started, the
file is removed at once; within a removals_after() block, a removal waits
for the block's end. Then: the files that Blenders which have ended
left behind are removed, and no others, by a process's first hand-over,
which does not wait for that. Prints 'REMOVAL OK'; the
test checks that <folder> is empty once Blender has ended (Python waits for
the last removal's thread, still running when this script ends).

  blender -b --addons hbao --python scratch_removal.py -- <folder>
"""
import os
import subprocess
import sys
import threading
import time

import bpy
from hbao import handover, scratch_files

folder = sys.argv[sys.argv.index("--") + 1]
release = threading.Event()
remove = scratch_files._remove


def held_back(path):
    release.wait(30)
    if path.endswith("-2.exr"):
        time.sleep(1.0)  # still pending when the script ends
    remove(path)


scratch_files._remove = held_back  # the add-on's own function, not Blender's
paths = []
for number in range(3):
    path = os.path.join(folder, f"hbao-passes-test-{number}.exr")
    with open(path, "wb") as scratch:
        scratch.write(b"\0" * 4096)
    scratch_files.remove_later(path)
    paths.append(path)
assert all(os.path.exists(path) for path in paths)

# The next save waits for the first two removals, not for the third.
waiter = threading.Thread(target=scratch_files.wait_for_older_removals)
waiter.start()
time.sleep(0.3)
assert waiter.is_alive(), "the save did not wait for the older removals"
release.set()
waiter.join(30)
assert not waiter.is_alive()
assert not os.path.exists(paths[0]) and not os.path.exists(paths[1]), os.listdir(folder)

# A save right after waits for nothing: the third removal is the latest.
start = time.perf_counter()
scratch_files.wait_for_older_removals()
assert time.perf_counter() - start < 0.5
assert os.path.exists(paths[2]), "the latest removal should still be pending"

# Where no thread can be started (a process out of them), the file goes at
# once, in the caller's thread, and the hand-over goes on.
start_thread = threading.Thread.start


def refuse(thread):
    raise RuntimeError("can't start new thread")


path = os.path.join(folder, "hbao-passes-test-3.exr")
open(path, "wb").close()
threading.Thread.start = refuse
try:
    scratch_files.remove_later(path)
finally:
    threading.Thread.start = start_thread
assert not os.path.exists(path), "the file was not removed without a thread"

# In a removals_after() block (the engine's AO), a removal starts only when
# the block ends, however it ends: here by an error.
path = os.path.join(folder, "hbao-passes-test-4.exr")
open(path, "wb").close()
started = len(scratch_files._removals)
try:
    with scratch_files.removals_after():
        scratch_files.remove_later(path)
        assert len(scratch_files._removals) == started, "a removal started within the block"
        raise KeyError("the AO failed")
except KeyError:
    pass
assert len(scratch_files._removals) == started + 1, "the block's end started no removal"
scratch_files._removals[-1].join(30)
assert not os.path.exists(path), "the file was not removed after the block"

# A block within a block leaves its files to the outer one, and another
# thread's removal is not held back by this thread's block.
inner_path, other_path = (os.path.join(folder, f"hbao-passes-test-{n}.exr") for n in (5, 6))
for made in (inner_path, other_path):
    open(made, "wb").close()
with scratch_files.removals_after():
    with scratch_files.removals_after():
        scratch_files.remove_later(inner_path)
    assert len(scratch_files._removals) == started + 1, "the inner block's end started a removal"
    other = threading.Thread(target=scratch_files.remove_later, args=(other_path,))
    other.start()
    other.join(30)
    assert len(scratch_files._removals) == started + 2, "another thread's removal was held back"
    scratch_files._removals[-1].join(30)
    assert not os.path.exists(other_path)
    assert os.path.exists(inner_path)
scratch_files._removals[-1].join(30)
assert not os.path.exists(inner_path), "the file was not removed after the outer block"


# Files left by Blenders that ended (killed, or os._exit before the removal
# thread was done) go at a process's first hand-over (scratch_files._stale):
# this space's (this machine's boot and PID namespace) of processes that have
# ended, at once; another space's (another machine or container, whose
# process ids mean nothing here and whose clock may differ) once an hour old,
# even where its process id is alive here (a container's Blender was process
# 1); a name from before session 33, of an ended process, 10 minutes old.
os.environ[scratch_files.SCRATCH_FOLDER_VARIABLE] = folder
ended = subprocess.Popen(["true"])
ended.wait()
space, run = scratch_files._space, scratch_files._run
other_space = "0badcafe" if space != "0badcafe" else "0badf00d"
other_run = "12345678" if run != "12345678" else "87654321"
old = time.time() - scratch_files.UNPLACED_STALE_AGE_S - 60
older = time.time() - scratch_files.OTHER_SPACE_STALE_AGE_S - 60
names = {
    "stale": (f"hbao-passes-{ended.pid}-1-7-{space}-{other_run}.exr", old),
    "this space's, ended, fresh": (f"hbao-passes-{ended.pid}-1-8-{space}-{other_run}.exr", None),
    "this process id's earlier run": (
        f"hbao-passes-{os.getpid()}-1-3-{space}-{other_run}.exr", None),
    "another space's, an hour old, its id alive here": (
        f"hbao-passes-1-1-4-{other_space}-{run}.exr", older),
    "stale, before session 33": (f"hbao-passes-{ended.pid}-1-5.exr", old),
    "stale, before session 19's numbers": (f"hbao-passes-{ended.pid}-1.exr", old),
    "fresh, before session 33": (f"hbao-passes-{ended.pid}-1-8.exr", None),
    "this process's": (f"hbao-passes-{os.getpid()}-1-9-{space}-{run}.exr", older),
    "another space's, 11 minutes old, its id ended here": (
        f"hbao-passes-{ended.pid}-1-6-{other_space}-{other_run}.exr", old),
    "not a scratch file": ("hbao-passes-notes.exr", old),
    "no process id": (f"hbao-passes-{2 ** 80}-1-1.exr", old)}
for name, mtime in names.values():
    path = os.path.join(folder, name)
    open(path, "wb").close()
    if mtime is not None:
        os.utime(path, (mtime, mtime))
removed = sorted(os.path.basename(path) for path in scratch_files.remove_stale_scratch_files())
expected = sorted(names[kind][0] for kind in (
    "stale", "this space's, ended, fresh", "this process id's earlier run",
    "another space's, an hour old, its id alive here", "stale, before session 33",
    "stale, before session 19's numbers"))
assert removed == expected, (removed, expected)
for kind in ("fresh, before session 33", "this process's",
             "another space's, 11 minutes old, its id ended here", "not a scratch file",
             "no process id"):
    path = os.path.join(folder, names[kind][0])
    assert os.path.exists(path), kind
    os.remove(path)

# A process's first hand-over starts that removal and does not wait for it:
# here it is held until released, and the hand-over (which fails at once:
# nothing was rendered) comes back before.
stale = os.path.join(folder, names["stale"][0])
open(stale, "wb").close()
os.utime(stale, (old, old))
cleanup_release = threading.Event()
remove_stale = scratch_files.remove_stale_scratch_files


def held_cleanup():
    cleanup_release.wait(30)
    return remove_stale()


scratch_files.remove_stale_scratch_files = held_cleanup
scratch_files._stale_files_checked_at = None
try:
    start = time.perf_counter()
    try:
        handover.read_passes(bpy.context.scene, {})
        raise AssertionError("a hand-over with nothing rendered did not fail")
    except RuntimeError:  # no Render Result, or one without pixels
        pass
    assert time.perf_counter() - start < 10, "the first hand-over waited for the stale files"
    assert os.path.exists(stale), "the stale file went before its removal was released"
finally:
    cleanup_release.set()
for thread in list(scratch_files._removals):
    thread.join(30)
assert not os.path.exists(stale), "the first hand-over did not remove the stale file"

# A file left meanwhile (a Blender killed while this one renders an animation):
# the next hand-overs within STALE_CHECK_INTERVAL_S do not look again; the
# first after it does.
open(stale, "wb").close()
os.utime(stale, (old, old))


def hand_over():
    try:
        handover.read_passes(bpy.context.scene, {})
    except RuntimeError:  # nothing rendered, as above
        pass
    for thread in list(scratch_files._removals):
        thread.join(30)


hand_over()
assert os.path.exists(stale), "a hand-over looked for stale files again at once"
scratch_files._stale_files_checked_at -= scratch_files.STALE_CHECK_INTERVAL_S
hand_over()
assert not os.path.exists(stale), \
    "a hand-over STALE_CHECK_INTERVAL_S later did not remove the stale file"

# A hand-over from the engine's memory (pass_capture: 4.5+, Cycles) looks
# too: a process whose renders all took their passes from memory left a
# killed Blender's file (an EEVEE or border render's, up to a gigabyte of
# /dev/shm) for good (a review's find). Here the capture hands back nothing.
open(stale, "wb").close()
os.utime(stale, (old, old))
scratch_files._stale_files_checked_at -= scratch_files.STALE_CHECK_INTERVAL_S
take = handover.pass_capture.take
handover.pass_capture.take = lambda *args, **kwargs: ({}, 0.0)
try:
    hand_over()
finally:
    handover.pass_capture.take = take
assert not os.path.exists(stale), "a hand-over from memory did not remove the stale file"
print("REMOVAL OK", flush=True)
