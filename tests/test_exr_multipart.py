# SPDX-License-Identifier: GPL-2.0-or-later
"""Blender 5's multi-part multilayer EXRs (one part per pass, channels keeping
their full names) through the `hbao` tool and libhbao_exr.

The fixtures (scripts/render_blender5_multipart.py, Blender 5.0.1) are one
render saved four ways: multi-part 32-bit float ZIP, the same as a single
part (use_exr_interleave), and multi-part half-float PIZ and B44. OpenEXR's own tools
(exrheader, exrmultipart: Debian package openexr) say what the files hold and
make the files the reader must refuse, so no EXR is parsed or written by hand
here.
"""
import json
import os
import random
import re
import shutil
import subprocess

import numpy as np
import pytest

from conftest import FIXTURES, REPO

MULTIPART = "blender5_cycles_multipart"
INTERLEAVED = "blender5_cycles_multipart_interleaved"
HALF_PIZ = "blender5_half_piz_multipart"
HALF_B44 = "blender5_half_b44_multipart"
LAYER = "ViewLayer"
DEPTH = f"{LAYER}.Depth.Z"
NORMALS = [f"{LAYER}.Normal.{axis}" for axis in "XYZ"]
COMBINED = [f"{LAYER}.Combined.{channel}" for channel in "RGBA"]
# Blender 5 writes one part per pass: Combined, Depth, Normal.
PART_NAMES = [f"{LAYER}.Combined", f"{LAYER}.Depth", f"{LAYER}.Normal"]
EXIT_RUNTIME = 1
TOOL_TIMEOUT_S = 120
# Half floats have an 11-bit significand: a float rounded to half is within
# 2**-11 relative of it (values here are far from half's subnormal range).
HALF_RELATIVE_TOLERANCE = 2.0 ** -11
# Mutated copies of the multi-part fixture fed to the tool (as test_cli.py's
# fuzz test does for a single-part one; scripts/fuzz_cli.sh runs longer).
FUZZ_CASES = 200
# The three part headers of the fixture end before this byte: byte flips
# below it hit part names, windows, channel lists and chunk counts.
HEADER_BYTES = 1500


from hbao import exr_passes as exr  # noqa: E402  (conftest puts addon/ on sys.path)


# --- helpers -----------------------------------------------------------------

def fixture(name, suffix=".exr"):
    path = FIXTURES / f"{name}{suffix}"
    if not path.is_file():
        pytest.fail(f"{path} missing: run scripts/render_blender5_multipart.py "
                    f"(see tests/fixtures/README.md)")
    return path


def openexr_tool(name):
    path = shutil.which(name)
    if path is None:
        pytest.fail(f"{name} missing: apt-get install openexr")
    return path


def run_tool(tool, *arguments):
    return subprocess.run([str(tool)] + [str(a) for a in arguments], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, errors="replace",
                          timeout=TOOL_TIMEOUT_S)


def run_ok(tool, *arguments):
    completed = run_tool(tool, *arguments)
    assert completed.returncode == 0, completed.stderr
    return completed


def info(tool, path):
    return json.loads(run_ok(tool, "--info", "--json", path).stdout)


def exrheader(path):
    """{part index: {channel name: "16-bit floating-point" ...}} and the
    header text, as OpenEXR's C++ library reads the file. A single-part file
    is part None (exrheader prints no "part" line for it)."""
    text = subprocess.run([openexr_tool("exrheader"), str(path)], stdout=subprocess.PIPE,
                          text=True, check=True, timeout=TOOL_TIMEOUT_S).stdout
    parts, part = {}, None
    for line in text.splitlines():
        heading = re.fullmatch(r" part (\d+):", line)
        if heading:
            part = int(heading.group(1))
            continue
        channel = re.fullmatch(r"    (\S+), ([^,]+), sampling 1 1.*", line)
        if channel:
            parts.setdefault(part, {})[channel.group(1)] = channel.group(2)
    return parts, text


def compute_ao(tool, source, output, *extra):
    """AO of `source` with the fixtures' camera, read back through libhbao_exr."""
    run_ok(tool, source, "-o", output, "--camera", fixture(MULTIPART, ".camera.json"), *extra)
    return exr.read_channels(output, ["AO"])["AO"]


def assert_refused(tool, path, output, *fragments):
    """Exit 1 with a message naming the file and the problem, no output
    written, and the same refusal from libhbao_exr."""
    for arguments in ([path, "-o", output], ["--info", path]):
        completed = run_tool(tool, *arguments)
        assert completed.returncode == EXIT_RUNTIME, (completed.returncode, completed.stderr)
        assert f"hbao: error: {path}" in completed.stderr, completed.stderr
        for fragment in fragments:
            assert fragment in completed.stderr, completed.stderr
        assert "Sanitizer" not in completed.stderr
    assert not output.exists()
    with pytest.raises(exr.EXRFormatError) as refused:
        exr.channel_names(path)
    for fragment in fragments:
        assert fragment in str(refused.value)


def combine(tmp_path, name, *inputs, override=False):
    """A multi-part file made by OpenEXR's exrmultipart from `inputs`
    ("file.exr" or "file.exr:part")."""
    output = tmp_path / f"{name}.exr"
    command = [openexr_tool("exrmultipart"), "-combine", "-i", *[str(i) for i in inputs],
               "-o", str(output)]
    if override:
        # Takes the first input's display window (a shared attribute) for all parts.
        command += ["-override", "1"]
    subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, check=True,
                   timeout=TOOL_TIMEOUT_S)
    return output


# --- the fixtures ---------------------------------------------------------------

def test_fixtures_are_what_blender_5_writes():
    """Checked with OpenEXR's C++ library: three parts, one per pass, for the
    default layout; one part holding everything for the interleaved twin."""
    for name in (MULTIPART, HALF_PIZ):
        parts, text = exrheader(fixture(name))
        assert sorted(parts) == [0, 1, 2], name
        assert set(parts[0]) == set(COMBINED), name
        assert set(parts[1]) == {DEPTH}, name
        assert set(parts[2]) == set(NORMALS), name
        for part_name in PART_NAMES:
            assert f'name (type string): "{part_name}"' in text, name
        assert 'Software (type string): "Blender 5.' in text, name
    parts, text = exrheader(fixture(INTERLEAVED))
    assert list(parts) == [None]
    assert set(parts[None]) == set(COMBINED + [DEPTH] + NORMALS)
    assert 'Software (type string): "Blender 5.' in text
    # Colour depth 16 makes Combined half; Blender keeps Depth and Normal float.
    half_parts, text = exrheader(fixture(HALF_PIZ))
    assert set(half_parts[0].values()) == {"16-bit floating-point"}
    assert set(half_parts[1].values()) | set(half_parts[2].values()) == {
        "32-bit floating-point"}
    assert text.count("compression (type compression): piz") == 3


# --- the hbao tool ----------------------------------------------------------------

def test_info_lists_every_channel_of_every_part(hbao_tool):
    for name in (MULTIPART, HALF_PIZ):
        path = fixture(name)
        parts, _ = exrheader(path)
        description = info(hbao_tool, path)
        assert description["parts"] == 3
        assert description["layers"] == [LAYER]
        assert (description["width"], description["height"]) == (48, 32)
        listed = {channel["name"]: channel for channel in description["channels"]}
        expected_types = {"16-bit floating-point": "half", "32-bit floating-point": "float"}
        assert len(listed) == sum(len(channels) for channels in parts.values())
        for part, channels in parts.items():
            for channel_name, kind in channels.items():
                assert listed[channel_name]["part"] == part, (name, channel_name)
                assert listed[channel_name]["type"] == expected_types[kind], (name, channel_name)
                # Decoded: every pixel finite (Blender's sky depth is 1e10, finite).
                assert listed[channel_name]["finite"] == 48 * 32, (name, channel_name)
        text = run_ok(hbao_tool, "--info", path).stdout
        assert "  parts: 3\n" in text
        assert "layers with a Depth pass: ViewLayer\n" in text
        for channel_name in listed:
            assert f"    {channel_name} " in text
    assert info(hbao_tool, fixture(INTERLEAVED))["parts"] == 1


def test_channels_decode_to_the_single_part_twins_pixels(hbao_tool):
    """Same Render Result, same float pixels whatever the part layout: every
    channel's statistics are equal (only the part index differs)."""
    multi = {c["name"]: c for c in info(hbao_tool, fixture(MULTIPART))["channels"]}
    single = {c["name"]: c for c in info(hbao_tool, fixture(INTERLEAVED))["channels"]}
    assert set(multi) == set(single)
    for channel_name, stats in single.items():
        del stats["part"], multi[channel_name]["part"]
        assert multi[channel_name] == stats, channel_name


def test_ao_equals_the_ao_of_the_same_passes_in_one_part(hbao_tool, tmp_path):
    """Bit-identical, not approximately equal: both files hold the same float32
    Depth and Normal pixels (one Render Result saved twice, ZIP is lossless;
    checked here first), the camera is the same, and libhbao's output is a
    deterministic function of its inputs (bit-identical whatever the thread
    count and kernel). Any difference would be the reader's fault."""
    passes = [DEPTH] + NORMALS
    multi_passes = exr.read_channels(fixture(MULTIPART), passes)
    single_passes = exr.read_channels(fixture(INTERLEAVED), passes)
    for channel_name in passes:
        assert np.array_equal(multi_passes[channel_name], single_passes[channel_name])

    from_multi = compute_ao(hbao_tool, fixture(MULTIPART), tmp_path / "multi.exr")
    from_single = compute_ao(hbao_tool, fixture(INTERLEAVED), tmp_path / "single.exr")
    # A real image: some occlusion (the cube's foot), background at 1.
    assert from_multi.min() < 0.9 and from_multi.max() == 1.0
    assert np.array_equal(from_multi, from_single)

    # The other single-part route: hbao --keep-input's copy of the multi-part file.
    kept = tmp_path / "kept.exr"
    compute_ao(hbao_tool, fixture(MULTIPART), kept, "--keep-input")
    assert np.array_equal(compute_ao(hbao_tool, kept, tmp_path / "again.exr"), from_multi)


def test_half_piz_multipart_gives_the_same_ao(hbao_tool, tmp_path):
    """The PIZ file is the same render: Depth and Normal are float in it too
    (PIZ is lossless), so AO is bit-identical; Combined, stored as half, is
    the float Combined rounded to half."""
    names = [DEPTH] + NORMALS + COMBINED
    half = exr.read_channels(fixture(HALF_PIZ), names)
    full = exr.read_channels(fixture(MULTIPART), names)
    for channel_name in [DEPTH] + NORMALS:
        assert np.array_equal(half[channel_name], full[channel_name]), channel_name
    for channel_name in COMBINED:
        np.testing.assert_allclose(half[channel_name], full[channel_name],
                                   rtol=HALF_RELATIVE_TOLERANCE, atol=0)
    assert np.array_equal(compute_ao(hbao_tool, fixture(HALF_PIZ), tmp_path / "half.exr"),
                          compute_ao(hbao_tool, fixture(MULTIPART), tmp_path / "full.exr"))


def test_half_b44_multipart_gives_the_same_ao(hbao_tool, tmp_path):
    """B44 compresses half channels only: the float Depth and Normal parts
    cannot be made smaller, and each of their chunks is stored uncompressed,
    which OpenEXRCore 3.1 decoded as B44 (the Normal part scrambled: AO off
    by up to 0.97, exit 0). They are the float render's pixels exactly."""
    parts, text = exrheader(fixture(HALF_B44))
    assert text.count("compression (type compression): b44") == 3
    assert set(parts[2].values()) == {"32-bit floating-point"}
    names = [DEPTH] + NORMALS
    b44 = exr.read_channels(fixture(HALF_B44), names)
    full = exr.read_channels(fixture(MULTIPART), names)
    for channel_name in names:
        assert np.array_equal(b44[channel_name], full[channel_name]), channel_name
    assert np.array_equal(compute_ao(hbao_tool, fixture(HALF_B44), tmp_path / "b44.exr"),
                          compute_ao(hbao_tool, fixture(MULTIPART), tmp_path / "full.exr"))


def test_keep_input_copies_every_channel_of_every_part(hbao_tool, tmp_path):
    """One single-part output holding AO and every input channel with its own
    type and the same decoded values, and a header whose chunkCount (copied
    from the input's part 0) counts this file's chunks."""
    for name, compression, chunks in ((MULTIPART, "none", 32), (HALF_PIZ, "piz", 1),
                                      (HALF_PIZ, "zip", 2)):
        output = tmp_path / f"{name}_{compression}.exr"
        run_ok(hbao_tool, fixture(name), "-o", output, "--keep-input", "--compression",
               compression, "--camera", fixture(name, ".camera.json"))
        source = {c["name"]: c for c in info(hbao_tool, fixture(name))["channels"]}
        description = info(hbao_tool, output)
        assert description["parts"] == 1
        result = {c["name"]: c for c in description["channels"]}
        assert set(result) == set(source) | {"AO"}
        for channel_name, stats in source.items():
            del stats["part"], result[channel_name]["part"]
            assert result[channel_name] == stats, (name, channel_name)
        parts, text = exrheader(output)
        assert list(parts) == [None]
        input_parts, _ = exrheader(fixture(name))
        for channels in input_parts.values():
            for channel_name, kind in channels.items():
                assert parts[None][channel_name] == kind, (name, channel_name)
        assert "BlenderMultiChannel" in text
        assert f"compression (type compression): {compression}" in text
        count = re.search(r"chunkCount \(type int\): (\d+)", text)
        assert count is None or int(count.group(1)) == chunks, (name, compression, text)


def test_layer_flag_and_default_layer_on_multipart(hbao_tool, tmp_path):
    default = compute_ao(hbao_tool, fixture(MULTIPART), tmp_path / "default.exr")
    chosen = compute_ao(hbao_tool, fixture(MULTIPART), tmp_path / "chosen.exr",
                        "--layer", LAYER)
    assert np.array_equal(default, chosen)
    completed = run_tool(hbao_tool, fixture(MULTIPART), "-o", tmp_path / "none.exr",
                         "--layer", "Nope")
    assert completed.returncode == EXIT_RUNTIME
    assert 'no layer "Nope"' in completed.stderr and f'"{LAYER}"' in completed.stderr


# --- libhbao_exr (the add-on's reader) ------------------------------------------------

def test_library_reads_depth_and_normal_across_parts():
    """What the add-on's render hook asks for: Depth alone and Normal as one
    interleaved group, from different parts, in one call."""
    path = fixture(MULTIPART)
    assert exr.image_size(path) == (48, 32)
    names = exr.channel_names(path)
    assert names == sorted(COMBINED + [DEPTH] + NORMALS)
    assert names == exr.channel_names(fixture(INTERLEAVED))
    groups = exr.read_channel_groups(path, {"depth": DEPTH, "normal": NORMALS})
    reference = exr.read_channels(fixture(INTERLEAVED), [DEPTH] + NORMALS)
    assert groups["depth"].shape == (32, 48)
    assert groups["normal"].shape == (32, 48, 3)
    assert np.array_equal(groups["depth"], reference[DEPTH])
    for axis, channel_name in enumerate(NORMALS):
        assert np.array_equal(groups["normal"][:, :, axis], reference[channel_name])
    # Not constant: the camera sees floor, cube and sky (Blender's sky depth 1e10).
    assert groups["depth"].min() < 10.0 < 1e9 < groups["depth"].max()
    with pytest.raises(KeyError, match=f"{LAYER}.AO.Z"):
        exr.read_channels(path, [f"{LAYER}.AO.Z"])


# --- what the reader refuses ---------------------------------------------------------

def test_parts_with_different_data_windows_are_refused(hbao_tool, tmp_path):
    """The Depth part of the 48x32 Blender 5 file with a 64x48 Blender 3.4 file:
    passes that do not line up pixel for pixel."""
    path = combine(tmp_path, "mismatch", f"{fixture(MULTIPART)}:1",
                   FIXTURES / "cycles_float_zip.exr", override=True)
    assert_refused(hbao_tool, path, tmp_path / "out.exr",
                   "has data window (0, 0) - (63, 47) but part 0 has (0, 0) - (47, 31)",
                   "parts with different data windows are not supported")


def test_parts_with_different_display_windows_are_refused(hbao_tool, tmp_path):
    """exrmultipart will not make this (the display window is an attribute
    every part must share), so the Normal part's display window is patched
    in place: its max.x, the third int32 of the box2i value, 47 -> 63."""
    data = bytearray(fixture(MULTIPART).read_bytes())
    key = b"displayWindow\x00box2i\x00" + (16).to_bytes(4, "little")
    positions = [m.start() for m in re.finditer(re.escape(key), data)]
    assert len(positions) == 3
    max_x = positions[2] + len(key) + 8
    assert int.from_bytes(data[max_x:max_x + 4], "little", signed=True) == 47
    data[max_x:max_x + 4] = (63).to_bytes(4, "little", signed=True)
    path = tmp_path / "display_mismatch.exr"
    path.write_bytes(bytes(data))
    assert_refused(hbao_tool, path, tmp_path / "out.exr",
                   f'part 2 ("{LAYER}.Normal") has display window (0, 0) - (63, 31) but part 0 '
                   f"has (0, 0) - (47, 31)", "parts with different display windows")


def test_a_channel_name_in_two_parts_is_refused(hbao_tool, tmp_path):
    path = combine(tmp_path, "duplicate", f"{fixture(MULTIPART)}:1", fixture(INTERLEAVED))
    assert_refused(hbao_tool, path, tmp_path / "out.exr",
                   f"channel {DEPTH} is in part 0", "and in part 1",
                   "channel names must be unique across parts")


def test_a_tiled_part_is_refused(hbao_tool, tmp_path):
    tiled = tmp_path / "tiled.exr"
    subprocess.run([openexr_tool("exrmaketiled"), str(fixture(INTERLEAVED)), str(tiled)],
                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, check=True,
                   timeout=TOOL_TIMEOUT_S)
    path = combine(tmp_path, "with_tiled", f"{fixture(MULTIPART)}:0", tiled)
    assert_refused(hbao_tool, path, tmp_path / "out.exr",
                   "only scanline images are supported (part 1", "is tiled")


def test_fuzzed_multipart_inputs_never_crash(hbao_tool, tmp_path):
    """Truncations and byte flips in the three part headers or anywhere:
    always exit 0 or 1, never a signal or a sanitizer report. Uses the
    AddressSanitizer build when it exists, else the normal one."""
    sanitized = REPO / "build-sanitize" / "hbao"
    tool = sanitized if sanitized.exists() else hbao_tool
    env = dict(os.environ, ASAN_OPTIONS="allocator_may_return_null=1:detect_leaks=1",
               UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1")
    data = fixture(HALF_PIZ).read_bytes()
    assert data.find(b"ViewLayer.Normal.Z") < HEADER_BYTES < len(data)
    rng = random.Random(5)
    mutated = tmp_path / "fuzz.exr"
    outcomes = {0: 0, EXIT_RUNTIME: 0}
    for case in range(FUZZ_CASES):
        content = bytearray(data)
        if case % 3 == 0:
            content = content[:rng.randrange(len(content))]
        else:
            span = HEADER_BYTES if case % 3 == 1 else len(content)
            for _ in range(rng.randrange(1, 16)):
                content[rng.randrange(span)] = rng.randrange(256)
        mutated.write_bytes(bytes(content))
        for arguments in ([mutated, "-o", tmp_path / "out.exr", "--keep-input"],
                          ["--info", mutated]):
            completed = subprocess.run([str(tool)] + [str(a) for a in arguments],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                       text=True, errors="replace", timeout=TOOL_TIMEOUT_S,
                                       env=env)
            assert completed.returncode in outcomes, (case, completed.stderr[-3000:])
            assert "Sanitizer" not in completed.stderr and "runtime error" not in completed.stderr
            if completed.returncode == EXIT_RUNTIME:
                assert "hbao: error: " in completed.stderr
            outcomes[completed.returncode] += 1
    # Both outcomes happen: the mutations neither all break nor all miss the file.
    assert outcomes[0] > 0 and outcomes[EXIT_RUNTIME] > 0, outcomes
