# SPDX-License-Identifier: GPL-2.0-or-later
"""addon/hbao/scratch_names.py without Blender: the add-on's stale-file
cleanup and the soak's leftover check recognise exactly the names the
hand-over gives its scratch files (tests/blender_scripts/scratch_removal.py
removes real ones)."""
import fnmatch
import os
import shutil
import subprocess
import sys

import pytest

from conftest import REPO  # noqa: F401  (puts the add-on on sys.path)
from hbao import scratch_names


def test_a_name_gives_back_its_owner():
    name = scratch_names.name(4242, 139872, 7, "0badcafe", "12345678")
    assert name == "hbao-passes-4242-139872-7-0badcafe-12345678.exr"
    assert scratch_names.owner_of(name) == (4242, "0badcafe", "12345678")
    assert fnmatch.fnmatchcase(name, scratch_names.glob_of(4242))
    assert not fnmatch.fnmatchcase(name, scratch_names.glob_of(424))


def test_names_before_sessions_19_and_33_and_other_files():
    assert scratch_names.owner_of("hbao-passes-4242-139872.exr") == (4242, None, None)
    assert scratch_names.owner_of("hbao-passes-4242-139872-7.exr") == (4242, None, None)
    for other in ("hbao-passes-notes.exr", "hbao-passes-4242-1-2.exr.tmp",
                  "hbao-passes--1-2.exr", "render-4242-1-2.exr", "hbao-passes-4242.exr"):
        assert scratch_names.owner_of(other) is None, other


def test_a_stereo_renders_view_files():
    """A stereo or multi-view save writes a file per view, its file suffix
    before the extension (view_files.view_path): recognised as the same
    process's, so that a killed Blender's view files are removed too."""
    name = scratch_names.name(4242, 139872, 7, "0badcafe", "12345678")
    for suffix in ("_L", "_R", "-center view"):
        owner = scratch_names.owner_of(name[:-len(".exr")] + suffix + ".exr")
        assert owner == (4242, "0badcafe", "12345678"), suffix
    assert scratch_names.owner_of(name[:-len(".exr")] + "_L.exr.tmp") is None


SPACE_AND_RUN = ("from hbao import scratch_files; "
                 "print(scratch_files._space, scratch_files._run)")


def test_each_blender_names_its_files_apart_and_knows_its_space():
    """Two processes of one machine and PID namespace share a space and
    differ in their run, so no two Blenders make one name, even with the
    same process and thread ids (two containers whose Blenders had the same
    ids, with address space randomisation off, made one name: one frame got
    another's AO, an exploratory run). A process of another PID namespace
    (unshare) has another space."""
    environment = dict(os.environ, PYTHONPATH=str(REPO / "addon"))
    command = [sys.executable, "-c", SPACE_AND_RUN]
    first, second = (subprocess.run(command, env=environment, check=True, text=True,
                                    stdout=subprocess.PIPE).stdout.split() for _ in range(2))
    assert first[0] == second[0] and first[1] != second[1], (first, second)
    assert all(len(part) == 8 and int(part, 16) >= 0 for part in first + second)
    if shutil.which("unshare") is None:
        pytest.fail("unshare missing: Debian's util-linux has it")
    namespaced = subprocess.run(["unshare", "--pid", "--fork", "--mount-proc"] + command,
                                env=environment, text=True, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT)
    # (needs root or user namespaces, which the project's machines allow)
    assert namespaced.returncode == 0, namespaced.stdout
    assert namespaced.stdout.split()[0] != first[0], namespaced.stdout


def test_view_files_stay_beside_the_scratch_file(tmp_path):
    """Each view's file lies beside the scratch file, named with its suffix;
    a suffix that would reach another folder (where the save would write and
    the removal then delete an artist's file) is refused before the save."""
    from hbao import view_files
    path = str(tmp_path / scratch_names.name(4242, 1, 0, "0badcafe", "12345678"))
    files = view_files.files(path, [("left", "_L"), ("right", "_R")])
    assert files == {"left": path[:-4] + "_L.exr", "right": path[:-4] + "_R.exr"}
    with pytest.raises(ValueError, match="folder separator"):
        view_files.files(path, [("left", "_L"), ("right", "/../../home/artist/shot")])


def test_a_scratch_folder_with_a_double_slash_is_absolute(monkeypatch):
    """HBAO_TEMP_DIR=//tmp ("$ROOT/tmp" with ROOT=/) is /tmp; Blender's save
    took "//" for a path relative to the .blend file and warned at every
    frame (4.5 to 5.3; an exploratory run)."""
    from hbao import scratch_files
    monkeypatch.setenv(scratch_files.SCRATCH_FOLDER_VARIABLE, "//tmp:relative:///var/tmp")
    assert scratch_files.folders() == ["/tmp", "relative", "/var/tmp"]


def test_a_process_that_cannot_place_itself_takes_a_space_of_its_own(monkeypatch):
    """Without the boot id or the PID namespace (no /proc, another system)
    a process cannot tell which process ids are its neighbours': its space is
    random, so every other process's files are another space's and wait an
    hour (a host name alone let one container remove another's file in use;
    a review)."""
    from hbao import scratch_files
    placed = scratch_files.process_space()
    assert placed == scratch_files.process_space() == scratch_files._space
    real_stat = os.stat

    def no_namespace(path, *args, **kwargs):
        if str(path) == "/proc/self/ns/pid":
            raise FileNotFoundError(path)
        return real_stat(path, *args, **kwargs)

    monkeypatch.setattr(scratch_files.os, "stat", no_namespace)
    unplaced = {scratch_files.process_space() for _ in range(4)}
    monkeypatch.setattr(scratch_files.os, "stat", real_stat)
    monkeypatch.setattr(scratch_files, "_read_text", lambda _path: "")
    unplaced |= {scratch_files.process_space() for _ in range(4)}
    assert len(unplaced) == 8 and placed not in unplaced, unplaced
