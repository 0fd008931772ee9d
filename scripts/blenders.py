# SPDX-License-Identifier: GPL-2.0-or-later
"""The Blenders this project runs in, and one way to start each (no bpy).

- Debian's `blender` (the application: headless with -b, and with a window
  under Xvfb for the UI),
- PyPI's `bpy` (Blender as a Python module, headless only) in the virtual
  environments scripts/setup_bpy.sh makes under BPY_ROOT.

The tests, the demo and the benchmark start Blender through `command()`, so a
script written for `blender -b` runs unchanged in either."""
import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BPY_RUNNER = REPO / "scripts" / "bpy_blender.py"
# Run before every UI script: no splash over the window (Blender.command).
NO_SPLASH = "import bpy; bpy.context.preferences.view.show_splash = False"
# A UI run's X screen (xvfb-run), which Blender's window fills, and the 3D
# view's anti-aliasing, off unless a run asks for it (Blender's default, 8
# samples). On Mesa's llvmpipe the CPU draws every pixel, and the view drew
# each sample again: a redraw of the default window took 0.72 CPU s at
# 1280x1024 with it, 0.61 without, 0.38 without the view's overlays too,
# 0.04 with the view closed. The Blender runs of test_ui, test_faults_ui and test_viewport
# took 848 CPU s at 1280x1024 with the anti-aliasing (of 2550 CPU s for the
# whole pytest stage), 608 at 1024x768, 486 with it off in every run too,
# and 638 as here (test_viewport's runs ask for it): one run each, on 2
# pytest workers.
XVFB_SCREEN = (1024, 768)
NO_VIEW_ANTI_ALIASING = "bpy.context.preferences.system.viewport_aa = 'OFF'"
# Where scripts/setup_bpy.sh keeps its virtual environments: outside the
# checkout, so that every clone (and CI's fresh clone) reuses one download.
BPY_ROOT = Path(os.environ.get("HBAO_BPY_ROOT", Path.home() / ".cache" / "hbao" / "bpy"))
# The bpy environments setup_bpy.sh makes, by folder name, oldest first.
BPY_ENVIRONMENTS = ("bpy-4.5", "bpy-5.0", "bpy-5.2", "bpy-5-latest")


@dataclass(frozen=True)
class Blender:
    """One Blender: `kind` is 'app' (the blender executable) or 'bpy' (a
    Python with the bpy module). `name` is short and stable (test ids)."""
    name: str
    kind: str
    executable: str
    version: str = ""

    @property
    def has_ui(self):
        return self.kind == "app"

    @property
    def version_tuple(self):
        return tuple(int(part) for part in self.version.split(".")[:3] if part.isdigit())

    @property
    def draws_headless(self):
        """bpy 5.2+ draws with the gpu module without a window (gpu.init())."""
        return self.kind == "bpy" and self.version_tuple >= (5, 2)

    @property
    def supports_extensions(self):
        """Blender 4.2+ installs add-ons as extensions (blender_manifest.toml)."""
        return self.version_tuple >= (4, 2)

    def command(self, script=None, args=(), blend=None, addons=("hbao",), ui=False,
                output=None, frame=None, animation=None, view_anti_aliasing=False):
        """The command line that opens `blend` (or factory settings), enables
        `addons`, then renders `frame` or the `animation` (start, end) to
        `output`, or runs `script` with `args` after `--`. With `ui`, in a
        window under Xvfb (XVFB_SCREEN), the 3D view anti-aliased only with
        `view_anti_aliasing`."""
        if ui and not self.has_ui:
            raise ValueError(f"{self.name} has no user interface")
        if self.kind == "app":
            command = [self.executable]
            if not ui:
                command.append("-b")
            command += ["--factory-startup", "-noaudio"]
        else:
            command = [self.executable, str(BPY_RUNNER)]
        # Add-ons before the file, as an artist's preferences would have them:
        # the file's helper scene then finds its render engine registered.
        if addons:
            command += ["--addons", ",".join(addons)]
        if blend is not None:
            command.append(str(blend))
        if output is not None:
            command += ["-o", str(output)]
        if frame is not None:
            command += ["-f", str(frame)]
        if animation is not None:
            command += ["-s", str(animation[0]), "-e", str(animation[1]), "-a"]
        if script is not None:
            if self.kind == "app":
                command += ["--python-exit-code", "1"]
            if ui:
                # Blender's window starts under its splash where no file is
                # opened (and in newer Blenders, by their source, with a
                # file too where no preferences were ever saved, as in the
                # tests' fresh user folder, which also makes it the Quick
                # Setup), which would hide half of what the script's
                # screenshots show. The preference is read when the splash
                # is due, after the command line's scripts have run.
                preferences = NO_SPLASH if view_anti_aliasing \
                    else f"{NO_SPLASH}; {NO_VIEW_ANTI_ALIASING}"
                command += ["--python-expr", preferences]
            command += ["--python", str(script), "--"] + [str(a) for a in args]
        if ui:
            command = ["xvfb-run", "-a", "--server-num", str(_first_display()),
                       "-s", f"-screen 0 {XVFB_SCREEN[0]}x{XVFB_SCREEN[1]}x24"] + command
        return command


# xvfb-run -a takes the first display number from here whose lock file is
# free; two xvfb-runs that start at once can both find the same one free,
# and the later Xvfb then fails to start. Runners started side by side (the
# test suite's pytest workers) each set HBAO_XVFB_FIRST_DISPLAY to a range
# of their own.
XVFB_FIRST_DISPLAY = "HBAO_XVFB_FIRST_DISPLAY"


def _first_display():
    value = os.environ.get(XVFB_FIRST_DISPLAY, "99")
    if not value.isdigit():
        raise ValueError(f"{XVFB_FIRST_DISPLAY}={value!r}: give an X display number, such as 99")
    return int(value)


def _version_of(command):
    try:
        completed = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                   text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    for line in completed.stdout.splitlines():
        if line.startswith("Blender ") or line.startswith("VERSION "):
            return line.split()[1]
    return ""


def user_scripts_with_addon(folder):
    """Make `folder` (created where missing) a Blender user-scripts folder
    whose addons/hbao is this checkout's add-on, for BLENDER_USER_SCRIPTS;
    returns it as a Path."""
    folder = Path(folder)
    (folder / "addons").mkdir(parents=True, exist_ok=True)
    (folder / "addons" / "hbao").symlink_to(REPO / "addon" / "hbao")
    return folder


def private_config(user_scripts):
    """The preferences folder beside `user_scripts`, for BLENDER_USER_CONFIG,
    made where missing: Blender given a folder that does not exist quietly
    reads and saves the real user's preferences instead, where those exist
    (~/.config/blender/<version>/config; a review found the tests' recent
    files and an install's preferences there)."""
    folder = Path(user_scripts) / "config"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def user_folders(user_scripts):
    """The environment that gives a Blender `user_scripts` and its private
    preferences (private_config): every Blender this project starts, so
    that none reads or writes the real user's."""
    return {"BLENDER_USER_SCRIPTS": str(user_scripts),
            "BLENDER_USER_CONFIG": str(private_config(user_scripts))}


def debian_blender():
    """Debian's blender (or $BLENDER), or None when it is not installed."""
    path = shutil.which(os.environ.get("BLENDER", "blender"))
    if path is None:
        return None
    version = _version_of([path, "--version"]) or "?"
    return Blender(f"blender-{version}", "app", path, version)


def bpy_blenders():
    """The bpy environments setup_bpy.sh made, oldest first."""
    found = []
    for folder in BPY_ENVIRONMENTS:
        python = BPY_ROOT / folder / "bin" / "python"
        if not python.exists():
            continue
        version = _version_of([str(python), "-c",
                               "import bpy; print('VERSION', bpy.app.version_string.split()[0])"])
        if version:
            found.append(Blender(f"bpy-{version}", "bpy", str(python), version))
    return found


def all_blenders():
    """Every Blender here: Debian's first, then the bpy environments. The
    selection $HBAO_BLENDERS (comma-separated names or prefixes, e.g.
    'blender,bpy-5') keeps only the matching ones."""
    blenders = [b for b in [debian_blender()] if b is not None] + bpy_blenders()
    wanted = [w.strip() for w in os.environ.get("HBAO_BLENDERS", "").split(",") if w.strip()]
    if wanted:
        blenders = [b for b in blenders if any(b.name.startswith(w) for w in wanted)]
    return blenders


def extension_tool():
    """(python, blender_ext.py) of the newest bpy here: Blender's own
    extension tool (validate, build), which runs without Blender. None when
    no bpy 4.2+ is installed."""
    for blender in reversed(bpy_blenders()):
        found = sorted(Path(blender.executable).parents[1].glob(
            "lib/python3*/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
        if found:
            return blender.executable, str(found[-1])
    return None


if __name__ == "__main__":
    import sys
    if sys.argv[1:] == ["extension-tool"]:
        tool = extension_tool()
        if tool is None:
            sys.exit(1)
        print(*tool)
    else:
        for blender in all_blenders():
            print(blender.name, blender.kind, blender.executable)
