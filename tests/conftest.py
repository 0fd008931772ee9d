# SPDX-License-Identifier: GPL-2.0-or-later
"""Shared pytest fixtures: where the built library, the tool and Blender are,
and one way to run a Python script inside a real (headless or Xvfb) Blender
with the add-on from this checkout enabled.

The Blender matrix: a test that takes the `blender` fixture and is marked
`matrix` (test_addon.py marks all of its tests) runs once in every Blender
scripts/blenders.py finds: Debian's blender and the bpy builds that
scripts/setup_bpy.sh installs. Marked `ui` as well, it runs only where
Blender has a user interface (Debian's, under Xvfb). Other tests get Debian's
blender. The summary at the end counts the results per Blender."""
import collections
import contextlib
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scripts"))
sys.path.insert(0, str(REPO / "addon"))  # the add-on's bpy-free modules
import blenders  # noqa: E402
from hbao.callback_guard import FAILURE_MARK  # noqa: E402
BUILD = Path(os.environ.get("HBAO_BUILD_DIR", REPO / "build"))
LIBRARY = BUILD / "libhbao.so"
# The add-on's EXR reader (csrc/exr): the add-on and the tests read EXRs with it.
EXR_LIBRARY = BUILD / "libhbao_exr.so"
TOOL = BUILD / "hbao"
FIXTURES = REPO / "tests" / "fixtures"
SCRIPTS = REPO / "scripts"
BLENDER = shutil.which(os.environ.get("BLENDER", "blender"))
BLENDERS = blenders.all_blenders()
DEBIAN_BLENDER = next((b for b in BLENDERS if b.kind == "app"), blenders.debian_blender())
# Set by scripts/test.sh: every Blender of the matrix must be there (a missing
# one fails the run instead of shrinking the matrix).
EXPECTED_BLENDERS = int(os.environ.get("HBAO_EXPECTED_BLENDERS", "0"))

# Tests read Blender's EXRs in this process too, through the add-on's binding
# (addon/hbao/exr_passes.py), which finds the library through this variable.
os.environ["HBAO_EXR_LIBRARY"] = str(EXR_LIBRARY)

# Generous: Cycles renders of test scenes take seconds, EEVEE on llvmpipe
# tens of seconds; a hang must still end the test rather than the CI run.
BLENDER_TIMEOUT_S = 600


@pytest.fixture(scope="session")
def built_library():
    if not LIBRARY.exists():
        pytest.fail(f"{LIBRARY} missing: build with scripts/test.sh or cmake first")
    return LIBRARY


@pytest.fixture(scope="session")
def native(built_library):
    """The add-on's ctypes binding of libhbao, on this build's library."""
    os.environ["HBAO_LIBRARY"] = str(built_library)
    from hbao import native as module
    module.unload_library()
    return module


class _NodeView:
    """The library as the HBAO node outputs its AO: the helper's pass holds
    1 - AO and the node's group turns it back (hbao.pass_encoding), so the
    node's AO is the library's rounded once each way: its compute_ao
    returns that, the rest is the library's."""

    def __init__(self, library):
        self._library = library

    def __getattr__(self, name):
        return getattr(self._library, name)

    def compute_ao(self, *args, **kwargs):
        from hbao import pass_encoding
        ao = self._library.compute_ao(*args, **kwargs)
        return pass_encoding.node_ao(pass_encoding.occlusion_pass(ao))


@pytest.fixture(scope="session")
def node_native(native):
    """native, for the node's AO (_NodeView)."""
    return _NodeView(native)


@pytest.fixture(scope="session")
def hbao_tool():
    if not TOOL.exists():
        pytest.fail(f"{TOOL} missing: build with scripts/test.sh or cmake first")
    return TOOL


@contextlib.contextmanager
def small_tmpfs(folder, size):
    """`folder` (made here) as a tmpfs of `size` ("64k"), for a full disk:
    unmounted after the block. Needs root, as the test machines have."""
    folder.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert mounted.returncode == 0, f"cannot mount a tmpfs (root needed): {mounted.stdout}"
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=False)


@pytest.fixture(scope="session")
def blender_user_scripts(tmp_path_factory):
    """A Blender user-scripts folder whose addons/hbao is this checkout's add-on."""
    return blenders.user_scripts_with_addon(tmp_path_factory.mktemp("blender_user_scripts"))


def _addon_deprecation_filters():
    """PYTHONWARNINGS entries that show every DeprecationWarning raised in
    the add-on's own modules, which Python hides outside __main__: Blender's
    API warns of what a later version removes (bpy 5.3:
    Scene.compositing_node_group, gone in 6.0), and run_command fails a run
    that shows one. The Python of the bpy builds reads the variable;
    Blender's own does not."""
    root = REPO / "addon"
    modules = (".".join(path.relative_to(root).with_suffix("").parts).removesuffix(".__init__")
               for path in sorted((root / "hbao").rglob("*.py")))
    return ",".join(f"default::DeprecationWarning:{module}" for module in modules)


def addon_deprecations(log):
    """The lines of a Blender log where the add-on used a deprecated API."""
    return [line for line in log.splitlines()
            if "DeprecationWarning:" in line and f"{os.sep}hbao{os.sep}" in line]


def blender_environment(user_scripts, extra=None):
    env = dict(os.environ)
    env["PYTHONWARNINGS"] = _addon_deprecation_filters()
    env.update(blenders.user_folders(user_scripts))  # never the real user's preferences
    env["HBAO_LIBRARY"] = str(LIBRARY)
    env["HBAO_EXR_LIBRARY"] = str(EXR_LIBRARY)
    env["PYTHONUNBUFFERED"] = "1"
    env.pop("PYTHONPATH", None)
    # Compiled modules kept beside the config: Debian's Blender ships its
    # 1400 scripts without them, and under PYTHONDONTWRITEBYTECODE every
    # start compiled its startup modules and the add-on again (0.4 of its
    # start's CPU time). A prefix keeps them out of the checkout.
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPYCACHEPREFIX"] = str(Path(user_scripts) / "pycache")
    if extra:
        env.update(extra)
    return env


# The add-on's switch to the file round trip (pass_capture.py): the tests
# choose the route themselves (file_route), never the shell they run in.
PASSES_FROM_MEMORY = "HBAO_PASSES_FROM_MEMORY"


def _load_stuck_marks():
    spec = importlib.util.spec_from_file_location(
        "stuck_marks", REPO / "tests" / "blender_scripts" / "stuck_marks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def pytest_configure(config):
    os.environ.pop(PASSES_FROM_MEMORY, None)
    # Under pytest-xdist (scripts/test.sh runs the suite on one worker a
    # core) each worker starts its Xvfbs from display numbers of its own.
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")
    if worker.startswith("gw"):
        os.environ[blenders.XVFB_FIRST_DISPLAY] = str(200 + 100 * int(worker[2:]))
    config.addinivalue_line(
        "markers", "xdist_group(name): tests that share a module fixture run on one worker")
    config.addinivalue_line("markers", "matrix: runs once in every Blender of the matrix")
    config.addinivalue_line("markers", "ui: needs Blender's user interface (Xvfb)")
    config.addinivalue_line("markers", "extension: needs Blender 4.2+ (extensions)")
    config.addinivalue_line("markers", "min_blender(major, minor): needs that Blender or newer")


def pytest_sessionstart(session):
    if EXPECTED_BLENDERS and len(BLENDERS) < EXPECTED_BLENDERS:
        names = ", ".join(b.name for b in BLENDERS) or "none"
        raise pytest.UsageError(
            f"the Blender matrix needs {EXPECTED_BLENDERS} Blenders, found {names}: "
            f"run scripts/setup.sh and scripts/setup_bpy.sh")


def pytest_collection_modifyitems(items):
    """The modules that run on one worker (xdist_group) first: pytest-xdist
    hands out work in the order collected, and a group that starts last
    leaves the other worker idle until it ends (test_viewport.py, some two
    minutes)."""
    items.sort(key=lambda item: item.get_closest_marker("xdist_group") is None)


def pytest_generate_tests(metafunc):
    if "blender" not in metafunc.fixturenames:
        return
    if metafunc.definition.get_closest_marker("matrix") is None:
        candidates = [DEBIAN_BLENDER] if DEBIAN_BLENDER else []
    elif metafunc.definition.get_closest_marker("ui") is not None:
        candidates = [b for b in BLENDERS if b.has_ui]
    elif metafunc.definition.get_closest_marker("extension") is not None:
        candidates = [b for b in BLENDERS if b.supports_extensions]
    else:
        candidates = BLENDERS
    minimum = metafunc.definition.get_closest_marker("min_blender")
    if minimum is not None:
        candidates = [b for b in candidates if b.version_tuple >= tuple(minimum.args)]
    metafunc.parametrize("blender", candidates, ids=[b.name for b in candidates])


# The results per Blender and the steps and quits Blender refused for good,
# counted where the reports arrive: in pytest's own process, or in
# pytest-xdist's controller, which gets each worker's reports with their
# user_properties.
_OUTCOMES = collections.defaultdict(collections.Counter)
# What the test scripts ran with writes allowed, refused for good: stuck_marks.py
STUCK_MARKS = _load_stuck_marks()
# run_command's tally in this process ("script: LABEL" -> runs), handed on
# with the next report
_REFUSED = collections.Counter()
_REFUSED_REPORTED = collections.Counter()
_BLENDER_PROPERTY, _REFUSED_PROPERTY = "hbao_blender", "hbao_refused_for_good"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if _REFUSED:
        report.user_properties.append((_REFUSED_PROPERTY, dict(_REFUSED)))
        _REFUSED.clear()
    params = item.callspec.params.values() if hasattr(item, "callspec") else ()
    blender = next((p for p in params if isinstance(p, blenders.Blender)), None)
    if blender is not None:
        report.user_properties.append((_BLENDER_PROPERTY, blender.name))


def pytest_runtest_logreport(report):
    properties = dict(report.user_properties)
    _REFUSED_REPORTED.update(properties.get(_REFUSED_PROPERTY, {}))
    blender = properties.get(_BLENDER_PROPERTY)
    if blender is None:
        return
    if report.when == "call" or (report.when == "setup" and report.outcome != "passed"):
        _OUTCOMES[blender][report.outcome] += 1


def pytest_terminal_summary(terminalreporter):
    if _REFUSED_REPORTED:
        terminalreporter.section("Blender refused a step or the quit for good")
        terminalreporter.write_line(
            "these ran with writes allowed (docs/blender-integration.md, \"Rarely the refusal "
            "does not end\"); ui_stuck_writes.py's on purpose (script: what, runs):")
        for what, runs in sorted(_REFUSED_REPORTED.items()):
            terminalreporter.write_line(f"  {what}: {runs}")
    if not _OUTCOMES:
        return
    terminalreporter.section("tests per Blender")
    for blender in BLENDERS:
        counts = _OUTCOMES.get(blender.name)
        if counts:
            how = "application, headless and under Xvfb" if blender.has_ui \
                else "Python module, headless"
            terminalreporter.write_line(
                f"{blender.name:16} ({how}): {counts['passed']} passed, "
                f"{counts['failed']} failed, {counts['skipped']} skipped")


def _runner(blender, user_scripts):
    def run(script, *args, blend=None, ui=False, addon=True, env=None, check=True,
            timeout=BLENDER_TIMEOUT_S, debug_memory=False, addon_errors=False,
            view_anti_aliasing=False):
        command = blender.command(script, args, blend=blend, ui=ui,
                                  addons=("hbao",) if addon else (),
                                  view_anti_aliasing=view_anti_aliasing)
        if debug_memory and blender.kind == "app":  # bpy has no such option
            # Blender's allocator fills freed memory: reading it then crashes.
            command.insert(command.index(blender.executable) + 1, "--debug-memory")
        return run_command(command, user_scripts, env, check, timeout, addon_errors)
    return run


@pytest.fixture(scope="session")
def run_blender(blender_user_scripts):
    """run_blender(script, *args, blend=None, ui=False, addon=True, env=None,
    debug_memory=False, view_anti_aliasing=False)

    Runs `script` (a path) in Debian's Blender, factory settings, this
    checkout's add-on enabled unless addon=False. Headless, or with ui=True in
    a real window under xvfb-run (the 3D view anti-aliased as Blender's
    default has it only with view_anti_aliasing=True: blenders.py).
    Arguments after `--` reach the script via sys.argv. Returns the
    CompletedProcess; fails the test on a non-zero exit, showing Blender's
    output."""
    if DEBIAN_BLENDER is None:
        pytest.fail("blender not found: run scripts/setup.sh")
    return _runner(DEBIAN_BLENDER, blender_user_scripts)


@pytest.fixture
def file_route(monkeypatch):
    """The main passes handed over through the file round trip
    (handover.py), for the tests of that route's faults: Blender 3.4,
    EEVEE and tiled or border renders take it, while 4.5 and later take
    Cycles' passes from memory (pass_capture.py)."""
    monkeypatch.setenv(PASSES_FROM_MEMORY, "0")


@pytest.fixture
def run_in_blender(blender, blender_user_scripts):
    """run_blender for the test's own Blender: a matrix test's `blender`
    parameter (the bpy builds too), else Debian's."""
    return _runner(blender, blender_user_scripts)


def json_line(log, key):
    """The JSON a Blender script printed after "KEY " (the first such line);
    fails the test, showing the log's end, where there is none."""
    line = next((text for text in log.splitlines() if text.startswith(f"{key} ")), None)
    assert line is not None, log[-3000:]
    return json.loads(line[len(key) + 1:])


def _script_name(command):
    scripts = [Path(argument).name for argument in command if argument.endswith(".py")]
    return scripts[-1] if scripts else " ".join(command)


def run_command(command, user_scripts, env=None, check=True, timeout=BLENDER_TIMEOUT_S,
                addon_errors=False):
    """Run a Blender command line with this checkout's add-on and libraries.
    It runs in a session of its own: past the timeout the whole process
    group is killed (xvfb-run, its Xvfb and Blender; killing xvfb-run alone
    left Blender and Xvfb running), and the test fails with the output so far.
    An error the add-on's guarded callbacks logged (callback_guard.py, which
    keeps Blender from printing a traceback) fails the test too, unless the
    test injected it (`addon_errors`)."""
    process = subprocess.Popen(
        command, env=blender_environment(user_scripts, env), start_new_session=True,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="backslashreplace")
    try:
        stdout, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:  # the whole group ended meanwhile
            pass
        stdout, _ = process.communicate()
        pytest.fail(f"Blender did not end within {timeout} s (killed):\n"
                    f"{' '.join(command)}\n{stdout[-6000:]}")
    completed = subprocess.CompletedProcess(command, process.returncode, stdout)
    for label in STUCK_MARKS.stuck_labels(stdout):
        _REFUSED[f"{_script_name(command)}: {label}"] += 1
    if check and completed.returncode != 0:
        pytest.fail(f"Blender exited with {completed.returncode}:\n"
                    f"{' '.join(command)}\n{completed.stdout[-6000:]}")
    if not addon_errors and FAILURE_MARK in completed.stdout:
        pytest.fail(f"an add-on callback failed:\n{' '.join(command)}\n{completed.stdout[-6000:]}")
    deprecations = addon_deprecations(completed.stdout)
    if deprecations:
        pytest.fail(f"the add-on used a deprecated API:\n{' '.join(command)}\n"
                    + "\n".join(deprecations[:20]))
    return completed
