# SPDX-License-Identifier: GPL-2.0-or-later
"""Soak test of the add-on in a long animation render (issue 13, item 5).

  python3 scripts/soak_blender.py [--frames N] [--blender NAME] [--report PART.md]

1. Saves the standard test scene (tests/blender_scripts/addon_render.py with
   `save_blend`) at 96x64, Cycles 1 sample, one HBAO node whose Radius is
   keyframed from the first frame to the last, so that every frame computes a
   different AO.
2. Renders it as `blender -b FILE.blend -s 1 -e N -a` (or the same through
   scripts/bpy_blender.py for a bpy build) with scripts/soak_blender_probe.py
   reporting, per frame, the process's RSS, CPU time and timestamps.
3. Checks: the exit status; every frame's main output and File Output exist
   and hold an AO that was computed (min < 1, all finite) and that follows the
   keyframed radius; the add-on logged one AO computation per frame; no
   `hbao-passes-*` scratch file of the render's process is left (under
   /dev/shm, or the temp folder, which is a private one here); RSS growth from
   frame 10 to frame N; CPU time per frame steady.

Prints a summary, writes it as Markdown to --report, exits 1 if a check
fails. Needs the libraries built (build/ or $HBAO_BUILD_DIR)."""
import argparse
import json
import os
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "addon"))
import blenders  # noqa: E402
from hbao import scratch_names, timing_line  # noqa: E402

REPO = blenders.REPO
BUILD = Path(os.environ.get("HBAO_BUILD_DIR", REPO / "build"))
SCENE_SCRIPT = REPO / "tests" / "blender_scripts" / "addon_render.py"
PROBE = REPO / "scripts" / "soak_blender_probe.py"

DEFAULT_FRAMES = 250
# Small and cheap on purpose: the soak is about what stays behind from frame
# to frame (memory, files), not about render cost; the machine is shared.
RESOLUTION = (96, 64)
SAMPLES = 1
# The keyframed Radius (scene units; the corner scene is a few units across):
# from a tight to a wide radius, so the AO of every frame differs.
RADIUS_FIRST, RADIUS_LAST = 0.2, 1.5
# RSS is compared from this frame on: the first frames load kernels, the
# library and Python modules, which is start-up, not growth.
RSS_BASELINE_FRAME = 10
# Most RSS may grow from frame RSS_BASELINE_FRAME to the last: 50 MiB over 240
# frames is 0.2 MiB a frame; one 96x64 frame's passes are about 0.5 MiB, so a
# leak of a frame's buffers every frame would exceed it within ~100 frames.
RSS_GROWTH_LIMIT_MIB = 50.0
# The report traces RSS at about this many evenly spaced frames.
TRACE_POINTS = 5
# Frames compared for steadiness of time (the first and the last this many).
STEADY_WINDOW = 10
# The last frames' median CPU time per frame may be at most this multiple of
# the first frames'. CPU time, not wall time: the machine is shared and its
# load changes under us; work that grows per frame still shows in CPU time.
CPU_SLOWDOWN_LIMIT = 2.0
# Generous: a frame takes well under a second; a hang must still end the run.
SECONDS_PER_FRAME_LIMIT = 30
# The report names the first few other things left in the temp folder.
SHOWN_LEFTOVERS = 3
PROBE_LINE = re.compile(r"^HBAO-SOAK frame=(\d+) (.*)$")
MIB = 1024.0


def choose_blender(name):
    """Debian's blender by default; else the first Blender whose name starts with `name`."""
    if name in (None, "", "blender", "debian"):
        blender = blenders.debian_blender()
    else:
        blender = next((b for b in blenders.all_blenders() if b.name.startswith(name)), None)
    if blender is None:
        known = ", ".join(b.name for b in blenders.all_blenders()) or "none"
        sys.exit(f"soak_blender.py: no Blender named {name or 'blender'} (here: {known})")
    return blender


def environment(root):
    """The add-on from this checkout, private preferences and a private temp folder."""
    user_scripts = blenders.user_scripts_with_addon(root / "user_scripts")
    temp = root / "tmp"
    temp.mkdir()
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    env.update(blenders.user_folders(user_scripts))
    env.update(HBAO_LIBRARY=str(BUILD / "libhbao.so"),
               HBAO_EXR_LIBRARY=str(BUILD / "libhbao_exr.so"),
               PYTHONUNBUFFERED="1", TMPDIR=str(temp), TEMP=str(temp), TMP=str(temp))
    return env, temp


def save_scene(blender, env, blend, frames, output, control=False):
    """The test scene; `control`: its HBAO node muted, so the render hook runs
    but computes nothing (a scene without the node has no Composite node)."""
    spec = {"resolution": list(RESOLUTION), "samples": SAMPLES, "save_blend": str(blend),
            "nodes": [{"keyframes": [[1, RADIUS_FIRST], [frames, RADIUS_LAST]],
                       "mute": control}]}
    command = blender.command(SCENE_SCRIPT, [json.dumps(spec), output])
    completed = subprocess.run(command, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, timeout=600)
    if completed.returncode != 0 or not blend.is_file():
        sys.exit(f"soak_blender.py: saving the scene failed:\n{completed.stdout[-4000:]}")


def render_command(blender, blend, frames, output):
    """`-s 1 -e N -a` with the probe installed before the render starts."""
    render = ["-o", str(output / "frame_####"), "-s", "1", "-e", str(frames), "-a"]
    if blender.kind == "app":
        return blender.command(blend=blend) + [
            "--python-exit-code", "1", "--python", str(PROBE)] + render
    # bpy_blender.py runs --python after the render: run the probe first in
    # the same interpreter, then bpy_blender.py with the same options.
    launcher = ("import runpy, sys; runpy.run_path(sys.argv[1]); sys.argv = sys.argv[2:]; "
                "runpy.run_path(sys.argv[0], run_name='__main__')")
    return [blender.executable, "-c", launcher, str(PROBE), str(blenders.BPY_RUNNER),
            str(blend), "--addons", "hbao"] + render


def run_render(command, env, frames, log_path):
    samples, hook_ms, messages, pid = [], [], [], None
    start = time.monotonic()
    with open(log_path, "w") as log:
        process = subprocess.Popen(command, env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, errors="replace")
        pid = process.pid
        for line in process.stdout:
            log.write(line)
            line = line.rstrip("\n")
            match = PROBE_LINE.match(line)
            if match:
                fields = dict(item.split("=", 1) for item in match.group(2).split())
                samples.append({"frame": int(match.group(1)),
                                "rss_kib": int(fields["rss_kib"]),
                                "hwm_kib": int(fields["hwm_kib"]),
                                "anon_kib": int(fields["anon_kib"]),
                                "swap_kib": int(fields["swap_kib"]),
                                "cpu_s": float(fields["cpu_s"]),
                                "pre_cpu_s": float(fields["pre_cpu_s"]),
                                "pre_s": float(fields["pre_s"]),
                                "write_s": float(fields["write_s"])})
                pid = int(fields["pid"])
                if len(samples) % 50 == 0:
                    print(f"  frame {samples[-1]['frame']}: RSS "
                          f"{samples[-1]['rss_kib'] / MIB:.1f} MiB", flush=True)
                continue
            hook = timing_line.parse(line) if line.startswith("HBAO: ") else None
            if hook is not None:
                hook_ms.append((hook["total_ms"], hook["ao_ms"]))
            elif line.startswith("HBAO:") and "created helper scene" not in line:
                messages.append(line)
        try:
            returncode = process.wait(timeout=max(60, frames * SECONDS_PER_FRAME_LIMIT
                                                  - (time.monotonic() - start)))
        except subprocess.TimeoutExpired:
            process.kill()
            returncode = process.wait()
    return returncode, samples, hook_ms, messages, pid, time.monotonic() - start


def ao_statistics(tool, path):
    """The AO channel's statistics in a File Output EXR (None if unreadable or absent)."""
    completed = subprocess.run([str(tool), "--info", "--json", str(path)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, timeout=60)
    if completed.returncode != 0:
        return None
    for channel in json.loads(completed.stdout)["channels"]:
        # The File Output input is named HBAO0_AO; Blender stores a value as .V.
        if channel["name"].split(".")[0].endswith("_AO"):
            return channel
    return None


def check_outputs(tool, output, frames):
    missing, bad, means = [], [], {}
    for frame in range(1, frames + 1):
        main, nodes = output / f"frame_{frame:04d}.exr", output / f"nodes_{frame:04d}.exr"
        for path in (main, nodes):
            if not path.is_file():
                missing.append(path.name)
        if not nodes.is_file():
            continue
        ao = ao_statistics(tool, nodes)
        # min < 1: the AO was computed; the add-on's fallback on an error is AO = 1.
        if ao is None or ao["nonfinite"] != 0 or not 0 <= ao["min"] < 1 or ao["max"] > 1:
            bad.append(nodes.name)
        else:
            means[frame] = ao["mean"]
    return missing, bad, means


def median(values):
    return statistics.median(values) if values else float("nan")


def slope(xs, ys):
    """Least-squares slope of ys over xs: growth per frame, robust to one odd sample."""
    if len(xs) < 2:
        return float("nan")
    mean_x, mean_y = statistics.fmean(xs), statistics.fmean(ys)
    spread = sum((x - mean_x) ** 2 for x in xs)
    return sum((x - mean_x) * (y - mean_y) for x, y in zip(xs, ys)) / spread


def figures(samples, frames):
    by_frame = {s["frame"]: s for s in samples}
    ordered = [by_frame[f] for f in sorted(by_frame)]
    wall, cpu = [], []
    for index, sample in enumerate(ordered):
        # A frame's time runs from the previous frame's write (its own
        # render_pre for the first) to its own write: everything in between.
        previous = ordered[index - 1] if index else None
        wall.append(sample["write_s"] - (previous["write_s"] if previous else sample["pre_s"]))
        cpu.append(sample["cpu_s"] - (previous["cpu_s"] if previous else sample["pre_cpu_s"]))
    baseline = by_frame.get(RSS_BASELINE_FRAME)
    last = by_frame.get(frames)

    def growth_mib(key):
        return (last[key] - baseline[key]) / MIB if baseline and last else float("nan")

    growth = growth_mib("rss_kib")
    span = frames - RSS_BASELINE_FRAME
    steady = [s for s in ordered if s["frame"] >= RSS_BASELINE_FRAME]
    every = max(1, frames // TRACE_POINTS)
    trace = [f for f in sorted(set([1, RSS_BASELINE_FRAME, frames]
                                   + list(range(every, frames, every))))
             if f in by_frame]
    second_half = [s for s in ordered if s["frame"] > frames // 2]
    return {
        "rss_trace": ", ".join(f"{f}: {by_frame[f]['rss_kib'] / MIB:.0f}" for f in trace),
        "anon_baseline_mib": baseline["anon_kib"] / MIB if baseline else float("nan"),
        "anon_last_mib": last["anon_kib"] / MIB if last else float("nan"),
        "anon_growth_mib": growth_mib("anon_kib"),
        "anon_slope_kib": slope([s["frame"] for s in steady], [s["anon_kib"] for s in steady]),
        "rss_slope_kib": slope([s["frame"] for s in steady], [s["rss_kib"] for s in steady]),
        "anon_slope_late_kib": slope([s["frame"] for s in second_half],
                                     [s["anon_kib"] for s in second_half]),
        "swap_max_mib": max(s["swap_kib"] for s in ordered) / MIB if ordered else float("nan"),
        "rss_first_mib": ordered[0]["rss_kib"] / MIB if ordered else float("nan"),
        "rss_baseline_mib": baseline["rss_kib"] / MIB if baseline else float("nan"),
        "rss_last_mib": last["rss_kib"] / MIB if last else float("nan"),
        "rss_max_mib": max(s["rss_kib"] for s in ordered) / MIB if ordered else float("nan"),
        "hwm_last_mib": last["hwm_kib"] / MIB if last else float("nan"),
        "rss_growth_mib": growth,
        "rss_growth_per_frame_kib": growth * MIB / span if span > 0 else float("nan"),
        "wall_median_s": median(wall), "wall_first_s": median(wall[:STEADY_WINDOW]),
        "wall_last_s": median(wall[-STEADY_WINDOW:]),
        "cpu_median_s": median(cpu), "cpu_first_s": median(cpu[:STEADY_WINDOW]),
        "cpu_last_s": median(cpu[-STEADY_WINDOW:]),
        "frames_probed": len(ordered),
    }


def leftovers(pid, temp):
    """Scratch files of the render's process, and anything else left in its temp folder."""
    scratch = []
    folders = [Path("/dev/shm"), temp]
    if os.environ.get("HBAO_TEMP_DIR"):  # the add-on's override of its scratch folder
        folders.append(Path(os.environ["HBAO_TEMP_DIR"]))
    for folder in folders:
        if folder.is_dir() and pid is not None:
            scratch += [str(p) for p in folder.glob(scratch_names.glob_of(pid))]
    other = [str(p.relative_to(temp)) + ("/" if p.is_dir() else "")
             for p in temp.rglob("*") if str(p) not in scratch]
    return sorted(scratch), sorted(other)


def shown(command):
    """The command line with the work folder as WORK and the checkout's paths relative."""
    text = shlex.join(str(c) for c in command)
    text = re.sub(r"[^\s']*/hbao-soak-blender-[^/\s']+", "WORK", text)
    return text.replace(str(REPO) + "/", "")


def report(blender, frames, control, command, elapsed, returncode, fig, hook_ms, messages,
           missing, bad, means, scratch, other, failures):
    radius_trend = "not checked"
    if 1 in means and frames in means:
        radius_trend = f"{means[1]:.4f} (frame 1) to {means[frames]:.4f} (frame {frames})"
    lines = [
        f"### Animation render: {blender.name}, {frames} frames"
        + (" (control: HBAO node muted)" if control else ""),
        "",
        f"Command (WORK a fresh temp folder): `{shown(command)}`",
        "",
        f"- Scene: the test scene (addon_render.py), {RESOLUTION[0]}x{RESOLUTION[1]}, Cycles "
        f"{SAMPLES} sample, one HBAO node, Radius keyframed {RADIUS_FIRST} -> {RADIUS_LAST}.",
        f"- Exit status {returncode}; {elapsed:.0f} s in all; "
        f"{fig['frames_probed']}/{frames} frames reported by the probe; the add-on logged "
        f"{len(hook_ms)} AO computations.",
        f"- RSS: {fig['rss_first_mib']:.1f} MiB at frame 1, {fig['rss_baseline_mib']:.1f} MiB at "
        f"frame {RSS_BASELINE_FRAME}, {fig['rss_last_mib']:.1f} MiB at frame {frames} "
        f"(max {fig['rss_max_mib']:.1f}, peak VmHWM {fig['hwm_last_mib']:.1f}): growth "
        f"{fig['rss_growth_mib']:+.2f} MiB from frame {RSS_BASELINE_FRAME} to {frames}, "
        f"{fig['rss_growth_per_frame_kib']:+.1f} KiB per frame (limit "
        f"{RSS_GROWTH_LIMIT_MIB:.0f} MiB); least-squares slope from frame "
        f"{RSS_BASELINE_FRAME} on {fig['rss_slope_kib']:+.1f} KiB per frame.",
        f"- RSS by frame (MiB): {fig['rss_trace']}.",
        f"- RssAnon (private memory, what a leak grows): {fig['anon_baseline_mib']:.1f} MiB at "
        f"frame {RSS_BASELINE_FRAME}, {fig['anon_last_mib']:.1f} MiB at frame {frames}: growth "
        f"{fig['anon_growth_mib']:+.2f} MiB (same limit), slope {fig['anon_slope_kib']:+.1f} KiB "
        f"per frame, {fig['anon_slope_late_kib']:+.2f} KiB per frame over the second half; "
        f"swap used at most {fig['swap_max_mib']:.1f} MiB.",
        f"- Wall time per frame: median {fig['wall_median_s'] * 1000:.0f} ms; first "
        f"{STEADY_WINDOW} {fig['wall_first_s'] * 1000:.0f} ms, last {STEADY_WINDOW} "
        f"{fig['wall_last_s'] * 1000:.0f} ms (medians).",
        f"- CPU time per frame (all threads): median {fig['cpu_median_s'] * 1000:.0f} ms; first "
        f"{STEADY_WINDOW} {fig['cpu_first_s'] * 1000:.0f} ms, last {STEADY_WINDOW} "
        f"{fig['cpu_last_s'] * 1000:.0f} ms (limit: last <= {CPU_SLOWDOWN_LIMIT:g}x first).",
    ]
    if hook_ms:
        lines.append(f"- The add-on's hook per frame (its own log): median "
                     f"{median([h[0] for h in hook_ms]):.0f} ms in all, of which AO "
                     f"{median([h[1] for h in hook_ms]):.0f} ms.")
    lines += [
        f"- Outputs: {2 * frames - len(missing)}/{2 * frames} files present (frame_NNNN.exr and "
        f"nodes_NNNN.exr); {len(bad)} File Output AO invalid or not computed; mean AO "
        f"{radius_trend}.",
        f"- Left behind: {len(scratch)} hbao-passes scratch file(s) of the render's process; "
        f"{len(other)} other file(s) or folder(s) in its private temp folder"
        + (f" ({', '.join(other[:SHOWN_LEFTOVERS])})." if other else "."),
        f"- Add-on messages other than its per-frame timing: {len(messages)}.",
        "",
        "**Result: " + ("PASS**" if not failures else "FAIL**: " + "; ".join(failures)),
        "",
    ]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=DEFAULT_FRAMES)
    parser.add_argument("--blender", default="blender",
                        help="'blender' (Debian's) or a name from scripts/blenders.py, "
                             "e.g. bpy-5.0")
    parser.add_argument("--report", type=Path, help="write the Markdown section here")
    parser.add_argument("--keep", action="store_true", help="keep the work folder")
    parser.add_argument("--control", action="store_true",
                        help="the same render with the HBAO node muted: Blender's and the "
                             "hook's own memory and time, without the AO computation")
    parser.add_argument("--inject-leak-kib", type=int, default=0,
                        help="self-test: leak this many KiB per frame in the render process "
                             "(the memory check must then fail)")
    options = parser.parse_args(argv)
    if options.frames <= RSS_BASELINE_FRAME:
        parser.error(f"--frames must be more than {RSS_BASELINE_FRAME}")
    tool = BUILD / "hbao"
    for needed in (tool, BUILD / "libhbao.so", BUILD / "libhbao_exr.so"):
        if not needed.exists():
            sys.exit(f"soak_blender.py: {needed} missing: build first (scripts/soak.sh does)")

    blender = choose_blender(options.blender)
    root = Path(tempfile.mkdtemp(prefix="hbao-soak-blender-"))
    try:
        env, temp = environment(root)
        env["HBAO_SOAK_INJECT_LEAK_KIB"] = str(options.inject_leak_kib)
        output = root / "frames"
        output.mkdir()
        blend = root / "soak.blend"
        print(f"soak: {blender.name}: saving the scene, then rendering {options.frames} frames "
              f"in {root}", flush=True)
        save_scene(blender, env, blend, options.frames, output, options.control)
        command = render_command(blender, blend, options.frames, output)
        returncode, samples, hook_ms, messages, pid, elapsed = run_render(
            command, env, options.frames, root / "render.log")
        scratch, other = leftovers(pid, temp)
        missing, bad, means = check_outputs(tool, output, options.frames)
        expected_computations = options.frames
        if options.control:
            # A muted node passes its Image through and computes no AO.
            bad, means, expected_computations = [], {}, 0
        fig = figures(samples, options.frames)

        failures = []
        if returncode != 0:
            failures.append(f"exit status {returncode} (log: {root / 'render.log'})")
        if fig["frames_probed"] != options.frames:
            failures.append(f"{fig['frames_probed']} frames reported, {options.frames} expected")
        if len(hook_ms) != expected_computations:
            failures.append(f"{len(hook_ms)} AO computations logged, "
                            f"{expected_computations} expected")
        if not fig["rss_growth_mib"] <= RSS_GROWTH_LIMIT_MIB:
            failures.append(f"RSS grew {fig['rss_growth_mib']:.1f} MiB "
                            f"(limit {RSS_GROWTH_LIMIT_MIB:.0f})")
        if not fig["anon_growth_mib"] <= RSS_GROWTH_LIMIT_MIB:
            failures.append(f"RssAnon grew {fig['anon_growth_mib']:.1f} MiB "
                            f"(limit {RSS_GROWTH_LIMIT_MIB:.0f})")
        if not fig["cpu_last_s"] <= CPU_SLOWDOWN_LIMIT * fig["cpu_first_s"]:
            failures.append("CPU time per frame grew beyond "
                            f"{CPU_SLOWDOWN_LIMIT:g}x")
        if missing:
            failures.append(f"{len(missing)} output(s) missing, e.g. {missing[0]}")
        if bad:
            failures.append(f"{len(bad)} AO output(s) invalid, e.g. {bad[0]}")
        if len(means) >= 2 and means.get(1) == means.get(options.frames):
            failures.append("the AO of the first and last frames is the same: "
                            "the keyframed radius had no effect")
        if scratch:
            failures.append(f"{len(scratch)} scratch file(s) left: {scratch[0]}")
        if messages:
            failures.append(f"the add-on reported: {messages[0]}")
        # Blender's own files in the temp folder are shown, not failed: they
        # are not the add-on's (bpy leaves its empty blender_XXXXXX session
        # folders: bpy_blender.py ends with os._exit, skipping its clean-up).
        text = report(blender, options.frames, options.control, command, elapsed, returncode,
                      fig, hook_ms, messages, missing, bad, means, scratch, other, failures)
        print(text, flush=True)
        if options.report:
            options.report.parent.mkdir(parents=True, exist_ok=True)
            options.report.write_text(text)
        if failures and not options.keep:
            # The log is the evidence of a failure: keep it beside the report.
            if options.report:
                shutil.copy(root / "render.log",
                            options.report.with_name(options.report.stem + ".render.log"))
        return 1 if failures else 0
    finally:
        if options.keep:
            print(f"soak: kept {root}")
        else:
            shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
