# SPDX-License-Identifier: GPL-2.0-or-later
"""The `hbao` command-line tool on real EXR files written by Blender.

How outputs are checked without a hand-written EXR parser:
- `hbao --info --json FILE` reports what OpenEXRCore decodes (layout, channel
  types, per-channel min/max/mean and non-finite counts); it is the tool's own
  reader, so it is used for layout and statistics only.
- Per-pixel checks go through Blender, an independent EXR implementation: a
  Blender process exports the input's Depth pass (compositor Image node ->
  File Output as a single-layer EXR) and loads the AO, written a second time
  with `--ao-channel Y` (a channel Blender shows as grayscale), and the PNG
  preview, then saves the pixels as .npy files for numpy.
"""
import ctypes
import ctypes.util
import json
import os
import random
import re
import resource
import shutil
import signal
import socket
import stat
import struct
import subprocess
import tempfile
import threading
import time
import zlib
from pathlib import Path

import numpy as np
import pytest

from conftest import BLENDER_TIMEOUT_S, DEBIAN_BLENDER, FIXTURES, REPO, SCRIPTS, small_tmpfs

# Every fixture that holds a Depth pass, with the view layer the tool picks.
DEPTH_FIXTURES = ["cycles_float_zip", "cycles_half_piz", "cycles_float_none", "cycles_half_b44",
                  "cycles_half_b44_tail", "eevee_half", "ortho_float", "two_layers"]
# Fixtures read back pixel by pixel through Blender (one per engine and projection,
# plus the half-float twin of cycles_float_zip).
READBACK_FIXTURES = ["cycles_float_zip", "cycles_half_piz", "eevee_half", "ortho_float"]

TOOL_TIMEOUT_S = 120
EXIT_RUNTIME = 1
EXIT_USAGE = 2
# libhbao's contract: depths at or beyond this (and <= 0, non-finite) are
# background and get AO = 1 exactly (HBAO_DEFAULT_BACKGROUND_DEPTH in hbao.h).
BACKGROUND_DEPTH = 65504.0
# The PNG preview maps AO in [0, 1] to round(AO * 255): it differs from the
# EXR's AO by at most half a step, plus float32 rounding in the scaling.
PNG_TOLERANCE = 0.5 / 255.0 + 1e-6
# Statistics of the same float32 pixels computed by the tool (double sums in
# C) and by numpy (pairwise float64 sums) agree to double rounding; 1e-9
# relative is far above that and far below any real difference.
MEAN_RELATIVE_TOLERANCE = 1e-9
# Two renders of one scene (float and half colour depth) hold the same Depth,
# but their Normal passes may differ in the last float bits (Cycles sums
# samples across threads; the Normal.X means differed by 1e-10 relative in
# our renders). AO is continuous in the normal, so a few float32 ulps of AO
# may differ; 1e-5 bounds that with margin and is 400x below one 8-bit step.
# (Measured: identical AO, difference 0.)
HALF_FLOAT_AO_TOLERANCE = 1e-5
# How many mutated files per fixture the fuzz test feeds the tool: 25 x 8
# fixtures = 200 files, what the issue asked for; each runs twice.
FUZZ_CASES_PER_FIXTURE = 25
FUZZ_SEED = 2024
FUZZ_TIMEOUT_S = 900


# --- helpers -----------------------------------------------------------------

def fixture_path(name):
    path = FIXTURES / f"{name}.exr"
    if not path.is_file():
        pytest.fail(f"{path} missing: see tests/fixtures/README.md to render it")
    return path


def camera_path(name):
    path = FIXTURES / f"{name}.camera.json"
    if not path.is_file():
        pytest.fail(f"{path} missing: see tests/fixtures/README.md to render it")
    return path


def run_tool(tool, *arguments, env=None):
    return subprocess.run([str(tool)] + [str(a) for a in arguments], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, errors="replace",
                          timeout=TOOL_TIMEOUT_S, env=env)


def run_ok(tool, *arguments):
    completed = run_tool(tool, *arguments)
    assert completed.returncode == 0, completed.stderr
    return completed


def info(tool, path):
    completed = run_ok(tool, "--info", "--json", path)
    return json.loads(completed.stdout)


def channels_by_name(description):
    return {channel["name"]: channel for channel in description["channels"]}


# The view layer of fixtures with several, where a test names none (the tool
# asks for one: test_layer_selection).
FIXTURE_LAYERS = {"two_layers": "Back"}


def compute_ao(tool, name, output, *extra):
    """Runs the tool on fixture `name` with its camera (and its layer, where it
    has several); returns the CompletedProcess."""
    layer = () if "--layer" in extra or name not in FIXTURE_LAYERS else \
        ("--layer", FIXTURE_LAYERS[name])
    return run_ok(tool, fixture_path(name), "-o", output, "--camera", camera_path(name), *layer,
                  *extra)


def assert_clean_error(completed, status, *fragments):
    assert completed.returncode == status, (completed.returncode, completed.stderr)
    assert "hbao: error: " in completed.stderr
    for fragment in fragments:
        assert fragment in completed.stderr, completed.stderr


def leftover_temporary_files(folder):
    return [p.name for p in Path(folder).iterdir() if ".hbao-tmp-" in p.name]


def exr_attribute(name, kind, payload):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(payload)) + payload


def scanline_exr(channels, width, height, claimed_size=None, display_window=None,
                 data_origin=(0, 0), half=(), integers=(), attributes=b"", pixel_aspect=1.0):
    """A single-part, uncompressed scanline EXR of float channels (name ->
    float32 array of shape (height, width); those named in `half` are stored
    as half floats, those in `integers` as unsigned integers), written from the OpenEXR file
    layout so that tests can make inputs of any size, or a header whose
    claimed size (claimed_size=(w, h)) the file does not hold: then no chunk
    table and no chunks follow. The data window starts at `data_origin`
    (x, y); the display window (min x, min y, max x, max y) is the data
    window unless given. `attributes`: more header attributes, as
    exr_attribute makes them; `pixel_aspect`: pixelAspectRatio's."""
    claimed_width, claimed_height = claimed_size or (width, height)
    names = sorted(channels)
    # chlist: name, pixel type (1 half, 2 float), pLinear, 3 reserved, x/y sampling.
    kinds = {n: 0 if n in integers else 1 if n in half else 2 for n in names}
    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", kinds[n], 0, 1, 1)
                      for n in names) + b"\0"
    x0, y0 = data_origin
    box = struct.pack("<4i", x0, y0, x0 + claimed_width - 1, y0 + claimed_height - 1)
    display = struct.pack("<4i", *display_window) if display_window else box
    header = (struct.pack("<ii", 20000630, 2)
              + exr_attribute("channels", "chlist", chlist)
              + exr_attribute("compression", "compression", b"\0")
              + exr_attribute("dataWindow", "box2i", box)
              + exr_attribute("displayWindow", "box2i", display)
              + exr_attribute("lineOrder", "lineOrder", b"\0")
              + exr_attribute("pixelAspectRatio", "float", struct.pack("<f", pixel_aspect))
              + exr_attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + exr_attribute("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + attributes + b"\0")
    if claimed_size is not None:
        return header
    types = {0: "<u4", 1: "<f2", 2: "<f4"}
    rows = [b"".join(np.ascontiguousarray(channels[n][y], dtype=types[kinds[n]]).tobytes()
                     for n in names) for y in range(height)]
    chunks = [struct.pack("<ii", y0 + y, len(row)) + row for y, row in enumerate(rows)]
    offsets, position = [], len(header) + 8 * height
    for chunk in chunks:
        offsets.append(position)
        position += len(chunk)
    return header + struct.pack(f"<{height}Q", *offsets) + b"".join(chunks)


def png_header(path):
    """(width, height, bit depth, colour type) from the PNG signature and IHDR chunk."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    length, chunk_type = struct.unpack(">I4s", data[8:16])
    assert chunk_type == b"IHDR" and length == 13
    width, height, bit_depth, colour_type = struct.unpack(">IIBB", data[16:26])
    assert struct.unpack(">I", data[29:33])[0] == zlib.crc32(data[12:29])
    return width, height, bit_depth, colour_type


# --- Blender as an independent reader ----------------------------------------

READBACK_SCRIPT = r'''
import json
import os
import sys

import bpy
import numpy as np

job = json.load(open(sys.argv[sys.argv.index("--") + 1]))
scene = bpy.context.scene


def top_first(image, channel=0):
    width, height = image.size
    pixels = np.array(image.pixels[:], dtype=np.float32).reshape(height, width, -1)
    return np.ascontiguousarray(pixels[::-1, :, channel])


for item in job["depth"]:
    # The multilayer file's Depth pass through the compositor into a plain EXR.
    scene.render.resolution_x, scene.render.resolution_y = item["size"]
    scene.render.resolution_percentage = 100
    scene.use_nodes = True
    tree = scene.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    source = tree.nodes.new("CompositorNodeImage")
    source.image = bpy.data.images.load(item["exr"])
    source.layer = item["layer"]
    sink = tree.nodes.new("CompositorNodeOutputFile")
    sink.base_path = item["folder"]
    sink.format.file_format = "OPEN_EXR"
    sink.format.color_depth = "32"
    sink.format.color_mode = "RGB"
    sink.file_slots[0].path = "depth_"
    tree.links.new(source.outputs["Depth"], sink.inputs[0])
    composite = tree.nodes.new("CompositorNodeComposite")
    tree.links.new(source.outputs["Depth"], composite.inputs[0])
    scene.render.filepath = os.path.join(item["folder"], "composite_")
    bpy.ops.render.render(write_still=False)
    written = os.path.join(item["folder"], "depth_%04d.exr" % scene.frame_current)
    np.save(item["npy"], top_first(bpy.data.images.load(written)))

for item in job["images"]:
    np.save(item["npy"], top_first(bpy.data.images.load(item["path"])))
'''


@pytest.fixture(scope="module")
def readback(hbao_tool, run_blender, tmp_path_factory):
    """Per fixture of READBACK_FIXTURES: depth (from the input, via Blender),
    ao (the tool's EXR, via Blender), preview (the tool's PNG, via Blender)
    and the tool's --info of the same AO written with its default name."""
    folder = tmp_path_factory.mktemp("readback")
    job = {"depth": [], "images": []}
    tool_info = {}
    for name in READBACK_FIXTURES:
        description = info(hbao_tool, fixture_path(name))
        layer = description["layers"][0]
        compute_ao(hbao_tool, name, folder / f"{name}_ao.exr")
        compute_ao(hbao_tool, name, folder / f"{name}_y.exr", "--ao-channel", "Y",
                   "--preview", folder / f"{name}.png")
        tool_info[name] = info(hbao_tool, folder / f"{name}_ao.exr")
        (folder / name).mkdir()
        job["depth"].append({"exr": str(fixture_path(name)), "layer": layer,
                             "size": [description["width"], description["height"]],
                             "folder": str(folder / name),
                             "npy": str(folder / f"{name}_depth.npy")})
        job["images"].append({"path": str(folder / f"{name}_y.exr"),
                              "npy": str(folder / f"{name}_ao.npy")})
        job["images"].append({"path": str(folder / f"{name}.png"),
                              "npy": str(folder / f"{name}_png.npy")})
    (folder / "job.json").write_text(json.dumps(job))
    (folder / "readback.py").write_text(READBACK_SCRIPT)
    run_blender(folder / "readback.py", folder / "job.json", addon=False)
    return {name: {"depth": np.load(folder / f"{name}_depth.npy"),
                   "ao": np.load(folder / f"{name}_ao.npy"),
                   "preview": np.load(folder / f"{name}_png.npy"),
                   "info": tool_info[name],
                   "png_path": folder / f"{name}.png"}
            for name in READBACK_FIXTURES}


# --- reading Blender's files -------------------------------------------------

@pytest.mark.parametrize("name", DEPTH_FIXTURES)
def test_each_fixture_gives_an_ao_channel_in_unit_range(hbao_tool, tmp_path, name):
    output = tmp_path / "ao.exr"
    compute_ao(hbao_tool, name, output)
    source, result = info(hbao_tool, fixture_path(name)), info(hbao_tool, output)
    assert [c["name"] for c in result["channels"]] == ["AO"]
    ao = result["channels"][0]
    assert ao["type"] == "float"
    assert ao["nonfinite"] == 0
    assert ao["finite"] == source["width"] * source["height"]
    assert 0.0 <= ao["min"] and ao["max"] <= 1.0
    # Every fixture shows objects in contact with a floor and walls: some
    # pixel must be occluded, and the sky (or the far wall) must not be.
    assert ao["min"] < 0.9 and ao["max"] == 1.0
    for key in ("width", "height", "data_window", "display_window", "pixel_aspect_ratio"):
        assert result[key] == source[key]
    assert result["compression"] == "zip"


@pytest.mark.parametrize("name", READBACK_FIXTURES)
def test_background_is_one_and_blender_reads_the_same_ao(readback, name):
    depth, ao = readback[name]["depth"], readback[name]["ao"]
    assert depth.shape == ao.shape
    assert np.all(np.isfinite(ao)) and ao.min() >= 0.0 and ao.max() <= 1.0
    background = ~np.isfinite(depth) | (depth <= 0.0) | (depth >= BACKGROUND_DEPTH)
    # Each scene has sky above the far wall or around the props.
    assert background.sum() > 0 and (~background).sum() > 0
    # Exact: the library gives background exactly 1, and both files store float32.
    assert np.all(ao[background] == 1.0)
    # The tool's own reader and Blender agree on the AO it wrote.
    stats = channels_by_name(readback[name]["info"])["AO"]
    # cJSON prints 15 significant digits: enough to recover any float32 exactly.
    assert np.float32(stats["min"]) == ao.min() and np.float32(stats["max"]) == ao.max()
    assert stats["mean"] == pytest.approx(float(ao.astype(np.float64).mean()),
                                          rel=MEAN_RELATIVE_TOLERANCE)


def test_rows_are_not_flipped(readback):
    """Background pixels line up with the input's background, row by row: a
    flipped or shifted image would put AO < 1 on sky pixels."""
    depth, ao = readback["cycles_float_zip"]["depth"], readback["cycles_float_zip"]["ao"]
    background = depth >= BACKGROUND_DEPTH
    rows_with_sky = np.flatnonzero(background.any(axis=1))
    # The demo scene's sky is at the top, above the back wall.
    assert rows_with_sky.size > 0 and rows_with_sky[0] == 0
    assert np.all(ao[background] == 1.0)
    assert ao[~background].min() < 1.0


def test_half_float_input_gives_the_same_ao_as_float(hbao_tool, readback):
    """cycles_half_piz is the scene of cycles_float_zip saved with half colour
    depth and PIZ. Blender keeps Depth and Normal as 32-bit float even then
    (checked below), so the AO may differ only through the two renders' own
    float noise."""
    half = channels_by_name(info(hbao_tool, fixture_path("cycles_half_piz")))
    full = channels_by_name(info(hbao_tool, fixture_path("cycles_float_zip")))
    assert {c["type"] for n, c in half.items() if ".Combined." in n} == {"half"}
    for name in ("ViewLayer.Depth.Z", "ViewLayer.Normal.X", "ViewLayer.Normal.Y",
                 "ViewLayer.Normal.Z"):
        assert half[name]["type"] == full[name]["type"] == "float"
    assert half["ViewLayer.Depth.Z"] == full["ViewLayer.Depth.Z"]
    difference = np.abs(readback["cycles_half_piz"]["ao"] - readback["cycles_float_zip"]["ao"])
    assert difference.max() <= HALF_FLOAT_AO_TOLERANCE


def test_preview_png_matches_the_ao(readback):
    for name in READBACK_FIXTURES:
        ao, preview = readback[name]["ao"], readback[name]["preview"]
        height, width = ao.shape
        assert png_header(readback[name]["png_path"]) == (width, height, 8, 0)
        assert preview.shape == ao.shape
        assert np.abs(preview - ao).max() <= PNG_TOLERANCE


def test_keep_input_copies_every_channel_with_its_type(hbao_tool, tmp_path):
    for name in ("cycles_half_piz", "eevee_half", "cycles_float_zip", "cycles_float_none"):
        output = tmp_path / f"{name}.exr"
        compute_ao(hbao_tool, name, output, "--keep-input")
        source = channels_by_name(info(hbao_tool, fixture_path(name)))
        result = channels_by_name(info(hbao_tool, output))
        assert set(result) == set(source) | {"AO"}
        for channel, stats in source.items():
            # Same type, same decoded values: the copy is lossless.
            assert result[channel] == stats, channel
        assert result["AO"]["type"] == "float"


def test_an_output_named_by_the_inputs_descriptor_is_refused(hbao_tool, tmp_path):
    """-o /dev/fd/3 (a wrapper that forgot its `3>file`) or --preview
    /proc/self/fd/3: the tool opens its input as descriptor 3, so these
    names are the input once it is open. Looked at before the input was
    opened, they passed, and the rename replaced the input, exit 0 (an
    earlier --keep-input output as the input, which the render check lets
    through; a review's find). Refused as the input, which stays as it was."""
    source = tmp_path / "keep.exr"
    run_ok(hbao_tool, fixture_path("cycles_float_zip"), "-o", source, "--keep-input",
           "--no-normals")
    before = source.read_bytes()
    for arguments in (["-o", "/dev/fd/3"], ["-o", tmp_path / "ao.exr", "--preview",
                                            "/proc/self/fd/3"]):
        completed = run_tool(hbao_tool, source, *arguments, "--no-normals")
        assert_clean_error(completed, EXIT_USAGE, "is the input file")
        assert source.read_bytes() == before
    assert not (tmp_path / "ao.exr").exists()


def test_one_pixel_aspect_flag_takes_blenders_default_for_the_other(hbao_tool, tmp_path):
    """A render of pixel aspect X 1, Y 2 has the ratio 0.5 in its header.
    --pixel-aspect-y 2 alone (or a camera file with only that key) kept the
    header's 0.5 for X, counting the aspect twice (AO off by up to 0.25; a
    review's find). Either value given, the other is Blender's default 1:
    the header alone, both flags, and Y alone give the same AO; X alone
    (1) gives square pixels, as its AO with a square header does."""
    y, x = np.mgrid[0:48, 0:64].astype(np.float32)
    depth = 5.0 + 0.6 * np.sin(x / 4.0) * np.cos(y / 3.0)
    channels = {"ViewLayer.Depth.Z": depth}
    (tmp_path / "tall.exr").write_bytes(scanline_exr(channels, 64, 48, pixel_aspect=0.5))
    (tmp_path / "square.exr").write_bytes(scanline_exr(channels, 64, 48))
    from hbao import exr_passes

    def ao(source, *flags):
        output = tmp_path / f"ao_{len(list(tmp_path.iterdir()))}.exr"
        run_ok(hbao_tool, tmp_path / source, "-o", output, "--radius", "0.5", *flags)
        return exr_passes.read_channels(output, ["AO"])["AO"]

    header = ao("tall.exr")
    assert np.array_equal(ao("tall.exr", "--pixel-aspect-x", "1", "--pixel-aspect-y", "2"), header)
    assert np.array_equal(ao("tall.exr", "--pixel-aspect-y", "2"), header)
    assert np.array_equal(ao("tall.exr", "--pixel-aspect-x", "1"), ao("square.exr"))
    assert not np.array_equal(header, ao("square.exr"))


def test_keep_input_copies_an_attribute_of_a_type_of_its_own(hbao_tool, tmp_path):
    """A header attribute of a type OpenEXR does not know (a studio's own:
    the format allows it, exrheader reads it) failed --keep-input after the
    whole AO was computed ("the opaque type is not actually a built-in
    type"; a review's find): copied as its bytes, the run succeeds."""
    y, x = np.mgrid[0:12, 0:16].astype(np.float32)
    tag = exr_attribute("studioTag", "customBlob", b"\x01\x02\x03\xff")
    (tmp_path / "in.exr").write_bytes(scanline_exr(
        {"ViewLayer.Depth.Z": 5.0 + 0.5 * np.sin(x / 3.0)}, 16, 12, attributes=tag))
    run_ok(hbao_tool, tmp_path / "in.exr", "-o", tmp_path / "ao.exr", "--keep-input")
    assert tag in (tmp_path / "ao.exr").read_bytes()
    assert "ViewLayer.Depth.Z" in channels_by_name(info(hbao_tool, tmp_path / "ao.exr"))


def test_keep_input_output_is_valid_for_the_reference_openexr(hbao_tool, tmp_path):
    """exrheader (OpenEXR's C++ library) accepts the file and sees its channels."""
    exrheader = shutil.which("exrheader")
    if exrheader is None:
        pytest.fail("exrheader missing: apt-get install openexr")
    output = tmp_path / "kept.exr"
    compute_ao(hbao_tool, "cycles_half_piz", output, "--keep-input", "--compression", "piz")
    header = subprocess.run([exrheader, str(output)], stdout=subprocess.PIPE, text=True,
                            check=True, timeout=TOOL_TIMEOUT_S).stdout
    assert "AO, 32-bit floating-point" in header
    assert "ViewLayer.Combined.R, 16-bit floating-point" in header
    assert "compression (type compression): piz" in header
    assert "BlenderMultiChannel" in header


@pytest.mark.parametrize("compression", ["zip", "zips"])
def test_zip_chunks_read_to_the_bits_openexrcore_gives(hbao_tool, tmp_path, compression):
    """The tool inflates ZIP and ZIPS chunks with libdeflate and undoes
    OpenEXR's predictor and byte interleave itself (zip_chunks.c); the
    add-on's libhbao_exr leaves them to OpenEXRCore (zlib). Files written
    so (half and float channels, one frame whose last chunk has fewer
    lines, two layers) come through the tool's --keep-input copy to the
    same bits as OpenEXRCore reads them; a chunk damaged inside is a clean
    error."""
    from hbao import exr_passes
    for name in ("eevee_half", "cycles_float_zip", "cycles_half_zip_tail", "two_layers"):
        layer = ("--layer", "Front") if name == "two_layers" else ()
        zipped = tmp_path / f"{name}.{compression}.exr"
        run_ok(hbao_tool, fixture_path(name), "-o", zipped, "--keep-input",
               "--compression", compression, *layer)
        plain = tmp_path / f"{name}.none.exr"
        run_ok(hbao_tool, zipped, "-o", plain, "--keep-input", "--compression", "none", *layer)
        names = [n for n in exr_passes.channel_names(zipped) if n != "AO"]
        assert len(names) >= 4, names
        expected = exr_passes.read_channels(zipped, names)
        copied = exr_passes.read_channels(plain, names)
        for channel in names:
            assert expected[channel].tobytes() == copied[channel].tobytes(), (name, channel)
    data = bytearray(zipped.read_bytes())
    middle = len(data) - 300  # inside the last chunk's deflate stream
    data[middle:middle + 16] = bytes(16)
    damaged = tmp_path / "damaged.exr"
    damaged.write_bytes(bytes(data))
    completed = run_tool(hbao_tool, damaged, "-o", tmp_path / "out.exr")
    assert_clean_error(completed, EXIT_RUNTIME, "damaged.exr", "chunk")


def _libdeflate():
    library = ctypes.CDLL(ctypes.util.find_library("deflate") or "libdeflate.so.0")
    library.libdeflate_alloc_compressor.restype = ctypes.c_void_p
    library.libdeflate_alloc_compressor.argtypes = [ctypes.c_int]
    library.libdeflate_zlib_compress.restype = ctypes.c_size_t
    library.libdeflate_zlib_compress.argtypes = [ctypes.c_void_p, ctypes.c_char_p,
                                                 ctypes.c_size_t, ctypes.c_char_p,
                                                 ctypes.c_size_t]
    library.libdeflate_free_compressor.argtypes = [ctypes.c_void_p]
    return library


def zip_chunk_size(chunk):
    """The size of one ZIP chunk deflated as the tool deflates it (libdeflate
    at ZIP_CHUNKS_LEVEL, csrc/tool/zip_chunks.h) after the OpenEXR file
    layout's reordering: the bytes split into even and odd halves, then each
    byte stored as its difference from the one before, plus 128."""
    level = int(re.search(r"#define ZIP_CHUNKS_LEVEL (\d+)",
                          (REPO / "csrc" / "tool" / "zip_chunks.h").read_text()).group(1))
    raw = np.frombuffer(chunk, np.uint8)
    split = np.concatenate([raw[0::2], raw[1::2]]).astype(np.int32)
    split[1:] = (split[1:] - split[:-1] + 128) & 255
    data = split.astype(np.uint8).tobytes()
    library = _libdeflate()
    deflater = library.libdeflate_alloc_compressor(level)
    assert deflater, f"libdeflate has no compressor of level {level}"
    out = ctypes.create_string_buffer(2 * len(data) + 1024)
    try:
        return library.libdeflate_zlib_compress(deflater, data, len(data), out, len(out))
    finally:
        library.libdeflate_free_compressor(deflater)


def chunk_of_exactly_its_own_size():
    """Channels for a 1 x 16 frame (one ZIP chunk: AO, Depth.Z and 40 kept
    channels, in name order) whose deflated bytes come to exactly the
    chunk's own size, as the tool deflates them. The depths are background,
    so the AO is 1 everywhere; the kept channels are random bytes with a
    quarter of them zero, which brings deflate down from storing the chunk
    (11 bytes more) through its size."""
    for fraction in np.linspace(0.2, 0.3, 41):
        for seed in range(20):
            rng = np.random.default_rng(seed)
            exponents = rng.integers(144, 253, size=(16, 1)).astype(np.uint32) << 23
            channels = {"Depth.Z": (exponents | rng.integers(0, 1 << 23, size=(16, 1))
                                    .astype(np.uint32)).view(np.float32)}
            for k in range(40):
                raw = rng.integers(0, 256, size=(16, 4), dtype=np.uint8)
                raw[rng.random(raw.shape) < fraction] = 0
                values = raw.view("<f4")
                channels[f"X{k:02d}"] = np.where(np.isfinite(values), values, 0).astype("<f4")
            everything = dict(channels, AO=np.ones((16, 1), np.float32))
            chunk = b"".join(everything[name][y].tobytes()
                             for y in range(16) for name in sorted(everything))
            if zip_chunk_size(chunk) == len(chunk):
                return channels
    pytest.fail("no chunk of its own deflated size found: has libdeflate changed?")


def test_a_zip_chunk_that_does_not_shrink_is_stored(hbao_tool, tmp_path):
    """A chunk whose deflated bytes come to exactly its own size is read
    back as stored: OpenEXRCore (3.1.5 here; its issue 2306) kept the zlib
    bytes, and the output came back as garbage (exr_writer.c). The tool now
    deflates ZIP chunks itself (compress_zip, zip_chunks_compress), and
    stores such a chunk as its packed bytes."""
    source = tmp_path / "in.exr"
    source.write_bytes(scanline_exr(chunk_of_exactly_its_own_size(), 1, 16))
    described = {}
    for compression in ("zip", "none"):
        output = tmp_path / f"{compression}.exr"
        run_ok(hbao_tool, source, "-o", output, "--keep-input", "--compression", compression)
        described[compression] = [dict(c, part=0) for c in info(hbao_tool, output)["channels"]]
    given = [dict(c, part=0) for c in info(hbao_tool, source)["channels"]]
    assert described["zip"] == described["none"]
    assert [c for c in described["zip"] if c["name"] != "AO"] == given
    # The case was met: the one chunk is stored at its packed size (a
    # deflate that compresses otherwise would make this chunk smaller, and
    # the test no test of it).
    assert first_chunk_size(tmp_path / "zip.exr") == 16 * 42 * 4


def first_chunk(path):
    """(where its data starts, its data size) of the first chunk of a
    single-part scanline EXR."""
    data = Path(path).read_bytes()
    at = 8
    while data[at] != 0:  # attributes: name, type, size, value
        at = data.index(b"\0", data.index(b"\0", at) + 1) + 1
        at += 4 + struct.unpack_from("<i", data, at)[0]
    offset = struct.unpack_from("<Q", data, at + 1)[0]
    return offset + 8, struct.unpack_from("<i", data, offset + 4)[0]  # after y and size


def first_chunk_size(path):
    """The data size of the first chunk of a single-part scanline EXR."""
    return first_chunk(path)[1]


@pytest.mark.parametrize("compression", ["zip", "piz", "zips", "rle", "none"])
def test_output_file_does_not_depend_on_the_thread_count(hbao_tool, tmp_path, compression):
    """Chunks are compressed by --threads threads and written in file order:
    every thread count gives the same bytes (the fixture's 48 rows make 3 ZIP
    chunks, 2 PIZ ones and 48 ZIPS ones)."""
    files = {}
    for threads in (1, 2, 3):
        output = tmp_path / f"ao_{threads}.exr"
        compute_ao(hbao_tool, "cycles_half_piz", output, "--keep-input", "--compression",
                   compression, "--threads", str(threads))
        files[threads] = output.read_bytes()
    assert files[2] == files[1]
    assert files[3] == files[1]
    assert info(hbao_tool, tmp_path / "ao_3.exr")["compression"] == compression


@pytest.mark.parametrize("threads", [1, 3])
def test_a_write_failure_midway_is_an_error_with_any_thread_count(hbao_tool, tmp_path, threads):
    """A file size limit that the header fits in but the chunks do not: the
    write fails part of the way through (with several threads, while other
    chunks wait for their turn); a clean error, no output, no temporary file."""
    def limit_file_size():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG instead of a kill
        resource.setrlimit(resource.RLIMIT_FSIZE, (20000, 20000))

    output = tmp_path / "ao.exr"
    completed = subprocess.run(
        [str(hbao_tool), str(fixture_path("cycles_float_none")), "-o", str(output),
         "--camera", str(camera_path("cycles_float_none")), "--keep-input",
         "--compression", "zip", "--threads", str(threads)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=TOOL_TIMEOUT_S,
        preexec_fn=limit_file_size)
    assert_clean_error(completed, EXIT_RUNTIME, "cannot encode a chunk", "File too large")
    assert not output.exists()
    assert leftover_temporary_files(tmp_path) == []


def test_layer_selection(hbao_tool, tmp_path):
    layers = info(hbao_tool, fixture_path("two_layers"))["layers"]
    assert layers == ["Back", "Front"]
    means = {}
    for layer in layers:
        output = tmp_path / f"{layer}.exr"
        compute_ao(hbao_tool, "two_layers", output, "--layer", layer)
        means[layer] = channels_by_name(info(hbao_tool, output))["AO"]["mean"]
    # "Front" holds props that "Back" excludes: more occlusion in front.
    assert means["Front"] < means["Back"]
    # Without --layer, which of several view layers a render's node reads
    # cannot be told (a default by name took "ViewLayer.001" over
    # "ViewLayer", silently: found by an exploratory run): an error lists them.
    ambiguous = run_tool(hbao_tool, fixture_path("two_layers"), "-o", tmp_path / "default.exr")
    assert_clean_error(ambiguous, EXIT_RUNTIME, "several view layers", "--layer", '"Back"',
                       '"Front"')
    assert not (tmp_path / "default.exr").exists()
    # With --back-layer naming one of them, the other is the one meant.
    back = run_ok(hbao_tool, fixture_path("two_layers"), "-o", tmp_path / "front.exr",
                  "--back-layer", "Back")
    assert back.returncode == 0
    missing = run_tool(hbao_tool, fixture_path("two_layers"), "-o", tmp_path / "x.exr",
                       "--layer", "Nope")
    assert_clean_error(missing, EXIT_RUNTIME, "Nope", '"Back"', '"Front"')
    assert not (tmp_path / "x.exr").exists()
    # A name longer than any channel: refused by the name given, whichever
    # flag gave it (--back-layer's was called --layer's)
    for flag in ("--layer", "--back-layer"):
        long_name = "Long" + "x" * 4096
        too_long = run_tool(hbao_tool, fixture_path("two_layers"), "-o", tmp_path / "x.exr",
                            "--layer" if flag == "--back-layer" else "--back-layer", "Back",
                            flag, long_name)
        assert_clean_error(too_long, EXIT_USAGE, 'layer "Longxxxx', "name too long")
        assert "--layer:" not in too_long.stderr
        assert not (tmp_path / "x.exr").exists()


def test_missing_depth_pass_is_an_error(hbao_tool, tmp_path):
    output = tmp_path / "ao.exr"
    completed = run_tool(hbao_tool, fixture_path("no_depth"), "-o", output)
    assert_clean_error(completed, EXIT_RUNTIME, "no Depth pass")
    assert not output.exists() and leftover_temporary_files(tmp_path) == []


def test_a_multi_view_render_in_one_file_says_to_save_each_view_alone(hbao_tool, tmp_path):
    """Views Format Multi-View saves every view in one file (3.4 and 4.5:
    channels "ViewLayer.Depth.left.Z"): the tool reads one view, from a
    file of its own, with that view's camera. It said "enable the Z/Depth
    pass", which was wrong (found by an exploratory run); now it names the
    views and how to save them."""
    depth = np.full((8, 8), 3.0, np.float32)
    source = tmp_path / "views.exr"
    source.write_bytes(scanline_exr({"ViewLayer.Depth.left.Z": depth,
                                     "ViewLayer.Depth.right.Z": depth}, 8, 8))
    completed = run_tool(hbao_tool, source, "-o", tmp_path / "ao.exr", "--no-normals")
    assert_clean_error(completed, EXIT_RUNTIME, 'holds the views "left", "right"',
                       "Views Format: Individual", "export_cameras.py")
    assert "enable the Z/Depth pass" not in completed.stderr
    assert not (tmp_path / "ao.exr").exists()
    # OpenEXR's own layout (exrmultiview) names the default view's channels
    # without a view: it was read as that view, silently (an exploratory run).
    source.write_bytes(scanline_exr({"ViewLayer.Depth.Z": depth,
                                     "ViewLayer.Depth.right.Z": depth}, 8, 8))
    completed = run_tool(hbao_tool, source, "-o", tmp_path / "ao.exr", "--no-normals")
    assert_clean_error(completed, EXIT_RUNTIME, 'holds the views "(default)", "right"',
                       "Views Format: Individual")
    assert not (tmp_path / "ao.exr").exists()


def test_a_layer_named_like_a_pass_is_no_view(hbao_tool, tmp_path):
    """A view layer whose name ends in ".Depth" ("BG.Depth": channels
    "BG.Depth.Depth.Z", "BG.Depth.Normal.Z") was taken for a multi-view
    render with views "Depth" and "Normal" and refused (an exploratory run):
    it is read as any layer is, and the AO is that of --layer BG.Depth; beside
    another layer, the tool asks for --layer, listing both; so for names
    with ".Depth." inside, and for Blender 3.4's single-view channels of
    such a layer (a review)."""
    depth = np.full((16, 16), 3.0, np.float32)
    depth[4:10, 4:10] = 2.5
    normal = {f"BG.Depth.Normal.{axis}": np.full((16, 16), value, np.float32)
              for axis, value in zip("XYZ", (0.0, 0.0, 1.0))}
    source = tmp_path / "bg.exr"
    source.write_bytes(scanline_exr({"BG.Depth.Depth.Z": depth, **normal}, 16, 16))
    flags = ("--radius", "1", "--blur", "0", "--world-to-camera", "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1")
    run_ok(hbao_tool, source, "-o", tmp_path / "found.exr", *flags)
    run_ok(hbao_tool, source, "-o", tmp_path / "named.exr", "--layer", "BG.Depth", *flags)
    from hbao import exr_passes
    found, named = (exr_passes.read_channels(tmp_path / f"{name}.exr", ["AO"])["AO"]
                    for name in ("found", "named"))
    assert found.min() < 0.95 and np.array_equal(found, named)
    source.write_bytes(scanline_exr({"BG.Depth.Depth.Z": depth, "FG.Depth.Z": depth, **normal},
                                    16, 16))
    refused = run_tool(hbao_tool, source, "-o", tmp_path / "two.exr", *flags)
    assert_clean_error(refused, EXIT_RUNTIME, "--layer NAME", '"BG.Depth", "FG"')
    # ".Depth." inside a name: a review found "A.Depth.B" listed as views
    inside = {f"A.Depth.B.{name[len('BG.Depth.'):]}": value for name, value in normal.items()}
    source.write_bytes(scanline_exr({"A.Depth.B.Depth.Z": depth, "FG.Depth.Z": depth, **inside},
                                    16, 16))
    for extra in ((), ("--layer", "Nope")):
        refused = run_tool(hbao_tool, source, "-o", tmp_path / "two.exr", *extra, *flags)
        assert_clean_error(refused, EXIT_RUNTIME, '"A.Depth.B", "FG"')
    # Blender 3.4's render with one view on ("<layer>.Depth.left.Z") of such
    # a layer: that view of layer "BG.Depth", as of any layer
    ao = {}
    for layer in ("BG.Depth", "BG"):
        view = {f"{layer}.Depth.left.Z": depth,
                **{f"{layer}.Normal.left.{axis}": value[-1:].repeat(16, 0)
                   for axis, value in zip("XYZ", normal.values())}}
        source.write_bytes(scanline_exr(view, 16, 16))
        run_ok(hbao_tool, source, "-o", tmp_path / f"view_{layer}.exr", *flags)
        ao[layer] = exr_passes.read_channels(tmp_path / f"view_{layer}.exr", ["AO"])["AO"]
    assert np.array_equal(ao["BG.Depth"], ao["BG"]) and np.array_equal(ao["BG"], found)
    # layers "BG" and "BG.Depth" side by side: "BG.Depth.Depth.Z" is no view
    # "Depth" of BG (--layer BG was refused so; a review)
    both = {"BG.Depth.Z": depth, "BG.Depth.Depth.Z": depth, **normal,
            **{f"BG.Normal.{axis}": value for axis, value in zip("XYZ", normal.values())}}
    source.write_bytes(scanline_exr(both, 16, 16))
    for layer in ("BG", "BG.Depth"):
        run_ok(hbao_tool, source, "-o", tmp_path / f"both_{layer}.exr", "--layer", layer, *flags)
        assert np.array_equal(
            exr_passes.read_channels(tmp_path / f"both_{layer}.exr", ["AO"])["AO"], found)
    # OpenEXR's multi-view layout (the default view unnamed) is refused
    # with --layer too, as without
    source.write_bytes(scanline_exr({"ViewLayer.Depth.Z": depth,
                                     "ViewLayer.Depth.right.Z": depth}, 16, 16))
    refused = run_tool(hbao_tool, source, "-o", tmp_path / "views.exr", "--layer", "ViewLayer",
                       "--no-normals")
    assert_clean_error(refused, EXIT_RUNTIME, 'holds the views "(default)", "right"')


@pytest.mark.matrix
def test_a_depth_stored_with_loss_is_read_with_a_warning(run_in_blender, blender, hbao_tool,
                                                         tmp_path):
    """Blender 3.4's File Output node writes a half-float multilayer EXR's
    Depth as half floats ("Depth.V"; 4.5 and later keep it float), and B44
    keeps about 6 bits of each value's difference in a 4x4 block: the AO
    from it differed from the lossless PIZ file's by up to 0.23 (mean 0.004)
    with no word. The tool warns where a pass it reads is stored so."""
    out = tmp_path / "out"
    completed = run_in_blender(SCRIPTS_IN_BLENDER / "file_output_half_b44.py", out)
    assert "FILE OUTPUT DONE" in completed.stdout, completed.stdout[-3000:]
    half = {}
    for codec in ("b44", "piz"):
        source = out / f"{codec}_0001.exr"
        half[codec] = channels_by_name(info(hbao_tool, source))["Depth.V"]["type"] == "half"
        run = run_ok(hbao_tool, source, "-o", tmp_path / f"ao_{codec}.exr", "--camera",
                     out / "camera.json")
        assert ('"Depth.V" is stored as half floats with B44 compression' in run.stderr) == \
            (codec == "b44" and half[codec]), run.stderr
    assert half["b44"] == (blender.version_tuple < (4, 5))


@pytest.mark.matrix
def test_a_multi_view_file_written_by_blender_says_to_save_each_view_alone(
        run_in_blender, blender, hbao_tool, tmp_path):
    """The same for the multi-view file Blender really writes: 3.4 and 4.5
    name its channels with the views, 5.x writes a part per view with the
    same channel names (the tool said "channel names must be unique across
    parts", not why)."""
    from test_addon import render
    out, _ = render(run_in_blender, tmp_path, {"stereo": True, "output_views_format": "MULTIVIEW",
                                               "nodes": [{"radius": 0.7}]})
    completed = run_tool(hbao_tool, out / "frame_0001.exr", "-o", tmp_path / "ao.exr",
                         "--no-normals")
    assert_clean_error(completed, EXIT_RUNTIME, "holds the views", '"left"', '"right"',
                       "Views Format: Individual")
    assert not (tmp_path / "ao.exr").exists()


def test_a_single_view_file_and_the_layers_listed(hbao_tool, tmp_path):
    """Blender 3.4 saves a render with one view on with the view in its
    channel names ("ViewLayer.Depth.left.Z"): the tool reads that view (it
    refused the file as one of several views: found by a review), with its
    Normal pass. A layer named by --back-layer is not listed among the
    layers to choose from."""
    depth = np.full((48, 64), 5.0, np.float32)
    depth[20:30, 20:30] = 4.5
    normal = {axis: np.full((48, 64), value, np.float32)
              for axis, value in (("X", 0.0), ("Y", -1.0), ("Z", 0.0))}
    outputs = []
    for view in (".left", ""):
        channels = {f"ViewLayer.Depth{view}.Z": depth}
        channels.update({f"ViewLayer.Normal{view}.{axis}": value
                         for axis, value in normal.items()})
        source = tmp_path / f"view{view}.exr"
        source.write_bytes(scanline_exr(channels, 64, 48))
        outputs.append(tmp_path / f"ao{view}.exr")
        run_ok(hbao_tool, source, "-o", outputs[-1], "--radius", "2", "--blur", "0",
               "--world-to-camera", "1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1")
    from hbao import exr_passes
    ao = [exr_passes.read_channels(path, ["AO"])["AO"] for path in outputs]
    assert ao[0].min() < 0.99 and np.array_equal(ao[0], ao[1])
    source = tmp_path / "three.exr"
    source.write_bytes(scanline_exr({f"{name}.Depth.Z": depth for name in "ABC"}, 64, 48))
    listed = run_tool(hbao_tool, source, "-o", tmp_path / "x.exr", "--back-layer", "C")
    assert_clean_error(listed, EXIT_RUNTIME, 'several view layers', '"A", "B"')
    assert '"C"' not in listed.stderr
    # The --back-layer's the only layer with a Depth pass: it was listed as
    # the one to choose (a review's find); the message says it is taken.
    alone = run_tool(hbao_tool, tmp_path / "view.exr", "-o", tmp_path / "x.exr", "--back-layer",
                     "ViewLayer")
    assert_clean_error(alone, EXIT_RUNTIME, "no Depth pass but the --back-layer's",
                       "(--layer NAME)")
    assert "layers with a Depth pass" not in alone.stderr


def test_a_normal_pass_missing_a_channel_is_said(hbao_tool, tmp_path):
    """A layer with part of a Normal pass (a channel lost in another
    program's edit) was computed from reconstructed normals without a word
    (a review's find): the warning says how many of the three are there.
    A whole Normal pass, or none (Depth alone, by choice), says nothing, and
    the partial pass gives the AO of none."""
    depth = np.full((12, 16), 5.0, np.float32)
    depth[4:8, 4:8] = 4.5
    flat = np.zeros((12, 16), np.float32)
    normal = {"X": flat, "Y": flat, "Z": np.ones((12, 16), np.float32)}
    cases = {"partial": ("X", "Y"), "whole": ("X", "Y", "Z"), "none": ()}
    ao = {}
    for case, axes in cases.items():
        channels = {"ViewLayer.Depth.Z": depth}
        channels.update({f"ViewLayer.Normal.{axis}": normal[axis] for axis in axes})
        (tmp_path / f"{case}.exr").write_bytes(scanline_exr(channels, 16, 12))
        completed = run_ok(hbao_tool, tmp_path / f"{case}.exr", "-o", tmp_path / f"{case}_ao.exr",
                           "--world-to-camera", "1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1")
        said = "the Normal pass has 2 of its 3 channels (ViewLayer.Normal.X/Y/Z)"
        assert (said in completed.stderr) == (case == "partial"), (case, completed.stderr)
        assert ("warning" in completed.stderr) == (case == "partial"), (case, completed.stderr)
        from hbao import exr_passes
        ao[case] = exr_passes.read_channels(tmp_path / f"{case}_ao.exr", ["AO"])["AO"]
    assert np.array_equal(ao["partial"], ao["none"])


def test_passes_stored_as_integers_are_refused(hbao_tool, tmp_path):
    """A Depth or Normal channel of unsigned integers (an index or ID pass
    under that name, from another program) was read as floats and gave AO
    from whatever the integers were, with no word (an exploratory run). It
    is refused, saying what it holds; integer normals can be left out."""
    depth = np.full((16, 16), 5.0, np.float32)
    depth[4:12, 4:12] = 4.0
    normals = {f"ViewLayer.Normal.{axis}": np.full((16, 16), value, np.float32)
               for axis, value in zip("XYZ", (0.0, 0.0, 1.0))}
    camera = tmp_path / "camera.json"
    camera.write_text(json.dumps({"lens": 20.0}))
    for name in ("ViewLayer.Depth.Z", "ViewLayer.Normal.Y"):
        source = tmp_path / f"{name}.exr"
        source.write_bytes(scanline_exr({"ViewLayer.Depth.Z": depth, **normals}, 16, 16,
                                        integers=(name,)))
        output = tmp_path / f"{name}_ao.exr"
        completed = run_tool(hbao_tool, source, "-o", output, "--camera", camera)
        assert_clean_error(completed, EXIT_RUNTIME, f'"{name}" holds unsigned integers')
        assert not output.exists()
        if "Normal" in name:
            assert "--no-normals" in completed.stderr
            run_ok(hbao_tool, source, "-o", output, "--camera", camera, "--no-normals")


def test_a_compression_newer_than_openexr_31_is_named_not_called_truncated(hbao_tool, tmp_path):
    """ZSTD (13) and HTJ2K (11, 12) came after OpenEXR 3.1, whose reader
    reports the compression attribute invalid and reads on with another: the
    tool said the file was cut short ("does not hold" its image, a corrupt
    chunk leader), for --info too. It now names the compression as unknown
    and says how to save the file (an exploratory run)."""
    depth = np.full((8, 8), 5.0, np.float32)
    plain = scanline_exr({"ViewLayer.Depth.Z": depth}, 8, 8)
    marker = exr_attribute("compression", "compression", b"\0")
    assert plain.count(marker) == 1
    for code in (11, 13):
        source = tmp_path / f"compression_{code}.exr"
        newer = exr_attribute("compression", "compression", bytes([code]))
        source.write_bytes(plain.replace(marker, newer))
        for arguments in (("--info", source), (source, "-o", tmp_path / "ao.exr")):
            assert_clean_error(run_tool(hbao_tool, *arguments), EXIT_RUNTIME,
                               "a compression that this OpenEXR library does not know",
                               f"Invalid value {code}", "save the EXR with ZIP")
    assert not (tmp_path / "ao.exr").exists()


def test_the_sky_of_a_long_clip_range_is_background(hbao_tool, tmp_path):
    """EEVEE in 4.5 and 5.0 writes the sky from a depth buffer that holds the
    far plane to about (clip end / clip start) x 2^-24 of it: 99864.38 for a
    clip end of 1e5, 699050.7 for 1e6 (clip start 0.1; a review). With the
    camera file's clip_start such a sky is background (the AO of a sky at
    1e10, exactly); a camera file without clip_start keeps the earlier rule,
    the lesser of 65504 and the clip end."""
    depth = np.full((48, 64), 5.1, np.float32)
    depth[16:30, 20:40] = 4.6
    ao = {}
    for name, sky, camera in (
            ("far", 1e10, {"clip_start": 0.1, "clip_end": 1e5}),
            ("1e5", 99864.38, {"clip_start": 0.1, "clip_end": 1e5}),
            ("1e6", 699050.7, {"clip_start": 0.1, "clip_end": 1e6}),
            ("old_file", 99864.38, {"clip_end": 1e5})):
        image = depth.copy()
        image[:16] = sky
        (tmp_path / f"{name}.exr").write_bytes(scanline_exr({"ViewLayer.Depth.Z": image}, 64, 48))
        (tmp_path / f"{name}.json").write_text(json.dumps(dict(camera, lens=20.0)))
        run_ok(hbao_tool, tmp_path / f"{name}.exr", "-o", tmp_path / f"{name}_ao.exr",
               "--camera", tmp_path / f"{name}.json", "--radius", "2", "--blur", "0")
        from hbao import exr_passes
        ao[name] = exr_passes.read_channels(tmp_path / f"{name}_ao.exr", ["AO"])["AO"]
    assert ao["far"].min() < 0.9
    for name in ("1e5", "1e6", "old_file"):
        assert np.array_equal(ao[name], ao["far"]), name


def test_geometry_past_65504_is_geometry_under_the_cameras_clip_end(hbao_tool, tmp_path):
    """A scene modelled in centimetres, or at kilometres: the tool took the
    smaller of 65504 and the camera's clip end for the background, so every
    depth past 65504 was background and the AO 1 everywhere, silently (an
    exploratory run). The scene below scaled by 2^14 (depths 75366 to
    91750, radius and clip end too) now gives its AO bit for bit (hbao.h,
    "Scale"); a depth of exactly 65504, EEVEE's half-float sky, is still
    background (here a strip in front of the box: the AO that a depth of
    1e10 there gives)."""
    scale = np.float32(2.0 ** 14)
    # no depth a half float (the library would take the image for EEVEE's
    # half-float Depth and allow for its rounding)
    depth = np.full((48, 64), 5.1, np.float32)
    depth[:16] = 5.600006  # the sky at the clip end, above a box before the wall
    depth[16:30, 20:40] = 4.6
    ao = {}
    for name, image, lengths in (("plain", depth, 1.0), ("scaled", depth * scale, scale),
                                 ("half_sky", depth * scale, scale),
                                 ("far_sky", depth * scale, scale)):
        image = image.copy()
        if name == "half_sky":
            image[36:40, 8:56] = 65504.0
        elif name == "far_sky":
            image[36:40, 8:56] = 1e10
        (tmp_path / f"{name}.exr").write_bytes(scanline_exr({"ViewLayer.Depth.Z": image}, 64, 48))
        (tmp_path / f"{name}.json").write_text(json.dumps(
            {"lens": 20.0, "clip_start": float(np.float32(0.1) * lengths),
             "clip_end": float(np.float32(5.6) * lengths)}))
        run_ok(hbao_tool, tmp_path / f"{name}.exr", "-o", tmp_path / f"{name}_ao.exr",
               "--camera", tmp_path / f"{name}.json", "--radius", repr(float(2.0 * lengths)),
               "--blur", "0")
        from hbao import exr_passes
        ao[name] = exr_passes.read_channels(tmp_path / f"{name}_ao.exr", ["AO"])["AO"]
    assert ao["plain"].min() < 0.9  # the box's foot and the wall's corner
    assert np.array_equal(ao["scaled"], ao["plain"])
    assert np.array_equal(ao["half_sky"], ao["far_sky"])
    assert not np.array_equal(ao["half_sky"], ao["scaled"])  # the strip mattered


def test_the_sky_at_the_cameras_clip_end_is_background(hbao_tool, tmp_path):
    """EEVEE in 4.5 and 5.0 writes the sky's Depth as the camera's Clip End
    (5.600006 for 5.6): with the camera file's clip_end (export_cameras.py
    writes it) such a depth is background, AO 1, as the node takes it; it
    was a wall that took AO from what stood before it. The rule is libhbao's
    (hbao_clip_background_depth), which the node takes too."""
    depth = np.full((48, 64), 5.0, np.float32)
    depth[:16] = 5.600006  # the sky, above a box standing before the wall
    depth[16:30, 20:40] = 4.5
    source = tmp_path / "sky.exr"
    source.write_bytes(scanline_exr({"ViewLayer.Depth.Z": depth}, 64, 48))
    ao = {}
    for name, description in (("with", {"lens": 20.0, "clip_end": 5.6}),
                              ("without", {"lens": 20.0})):
        (tmp_path / f"{name}.json").write_text(json.dumps(description))
        run_ok(hbao_tool, source, "-o", tmp_path / f"{name}.exr", "--camera",
               tmp_path / f"{name}.json", "--radius", "2", "--blur", "0")
        from hbao import exr_passes
        ao[name] = exr_passes.read_channels(tmp_path / f"{name}.exr", ["AO"])["AO"]
    assert ao["without"][:16].min() < 0.9  # the sky as a wall: shaded by the box
    assert np.all(ao["with"][:16] == 1.0)
    assert ao["with"][16:].min() < 0.9  # the box and wall keep their AO
    bad = tmp_path / "bad.json"
    for key in ("clip_end", "clip_start"):
        bad.write_text(json.dumps({key: -1}))
        refused = run_tool(hbao_tool, source, "-o", tmp_path / "bad.exr", "--camera", bad)
        assert_clean_error(refused, EXIT_RUNTIME, f'"{key}" must be > 0')


def test_a_file_output_nodes_depth_and_a_constant_depth(hbao_tool, tmp_path):
    """A File Output node's Depth input writes "Depth.V" (its Normal
    "Normal.X/Y/Z"): read as a render's Depth.Z is. A layer named too long
    for Blender before 5.0 to keep its Normal pass (56 bytes) says so (the
    normals were reconstructed silently); a short one of Depth alone, a
    choice, stays quiet. A depth
    that is the same everywhere (Blender writes a single-layer EXR's Z as 1
    where the Composite node's Z input is unlinked) gives AO 1 everywhere:
    the tool warns, where it said nothing (found by an exploratory run); a
    frame of background alone does not warn."""
    depth = np.full((48, 64), 5.0, np.float32)
    depth[20:30, 20:30] = 4.5
    flags = ("--no-normals", "--radius", "2", "--blur", "0")
    outputs = {}
    for name in ("Depth.V", "Depth.Z"):
        source = tmp_path / f"{name}.exr"
        source.write_bytes(scanline_exr({name: depth}, 64, 48))
        outputs[name] = tmp_path / f"ao_{name}.exr"
        completed = run_ok(hbao_tool, source, "-o", outputs[name], *flags)
        assert "every pixel's depth" not in completed.stderr
    from hbao import exr_passes
    ao = [exr_passes.read_channels(outputs[name], ["AO"])["AO"] for name in outputs]
    assert ao[0].min() < 0.99 and np.array_equal(ao[0], ao[1])
    long_name = "L" * 56
    for layer, warned in ((long_name, True), ("Short", False)):
        source = tmp_path / "layer.exr"
        source.write_bytes(scanline_exr({f"{layer}.Depth.Z": depth}, 64, 48))
        said = run_ok(hbao_tool, source, "-o", tmp_path / "layer_ao.exr", "--radius", "2")
        assert (f"no Normal pass ({layer}.Normal.X/Y/Z): normals are reconstructed"
                in said.stderr) == warned, said.stderr
        quiet = run_ok(hbao_tool, source, "-o", tmp_path / "layer_ao.exr", *flags)
        assert "Normal" not in quiet.stderr
    for value, warned in ((1.0, True), (1e10, False), (65504.0, False)):
        source = tmp_path / "flat.exr"
        source.write_bytes(scanline_exr({"Z": np.full((48, 64), value, np.float32)}, 64, 48))
        completed = run_ok(hbao_tool, source, "-o", tmp_path / "flat_ao.exr", *flags)
        assert ("every pixel's depth (Z) is 1: the AO is 1 everywhere" in completed.stderr) \
            == warned, (value, completed.stderr)
        assert exr_passes.read_channels(tmp_path / "flat_ao.exr", ["AO"])["AO"].min() == 1.0
    # An empty shot whose sky lies at the camera file's Clip End (EEVEE 4.5,
    # 5.0), or is EEVEE 3.x's 65504 under a farther one, is background: no
    # warning (a review found both warned).
    for value, clip_end in ((5.600006, 5.6), (65504.0, 1e6)):
        source = tmp_path / "flat.exr"
        source.write_bytes(scanline_exr({"Z": np.full((48, 64), value, np.float32)}, 64, 48))
        camera = tmp_path / "flat.json"
        camera.write_text(json.dumps({"lens": 20.0, "clip_end": clip_end}))
        completed = run_ok(hbao_tool, source, "-o", tmp_path / "flat_ao.exr", "--camera", camera,
                           *flags)
        assert "every pixel's depth" not in completed.stderr, (value, completed.stderr)


# --- camera ------------------------------------------------------------------

def test_camera_flags_override_the_file(hbao_tool, tmp_path):
    name = "cycles_float_zip"
    compute_ao(hbao_tool, name, tmp_path / "file.exr")
    camera = json.loads(camera_path(name).read_text())
    compute_ao(hbao_tool, name, tmp_path / "longer.exr", "--lens", str(camera["lens"] * 4))
    matrix = ",".join(str(v) for row in camera["world_to_camera"] for v in row)
    compute_ao(hbao_tool, name, tmp_path / "same.exr", "--lens", str(camera["lens"]),
               "--world-to-camera", matrix)
    stats = {key: channels_by_name(info(hbao_tool, tmp_path / f"{key}.exr"))["AO"]
             for key in ("file", "longer", "same")}
    # Restating the file's own values changes nothing; a 4x longer lens makes
    # the same radius cover 4x more pixels, which changes the AO.
    assert stats["same"] == stats["file"]
    assert stats["longer"]["mean"] != stats["file"]["mean"]


def test_normals_without_a_matrix_warn(hbao_tool, tmp_path):
    source = fixture_path("cycles_float_zip")
    warned = run_ok(hbao_tool, source, "-o", tmp_path / "a.exr")
    assert "hbao: warning: " in warned.stderr and "identity" in warned.stderr
    for extra in (["--no-normals"], ["--camera", camera_path("cycles_float_zip")]):
        quiet = run_ok(hbao_tool, source, "-o", tmp_path / "b.exr", *extra)
        assert quiet.stderr == ""


def test_a_camera_file_without_its_matrix_is_an_error_where_normals_are_used(
        hbao_tool, tmp_path):
    """A camera file (even "{}": valid JSON) without world_to_camera would
    turn the Normal pass by the identity and the frame would succeed, wrong
    (a farm keeps it): an error, in a sequence that frame's. With
    --no-normals or --world-to-camera it is a complete camera."""
    partial = tmp_path / "partial.json"
    camera = json.loads(camera_path("cycles_float_zip").read_text())
    matrix = camera.pop("world_to_camera")
    partial.write_text(json.dumps(camera))
    for content in ("{}", json.dumps(camera)):
        partial.write_text(content)
        completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o",
                             tmp_path / "o.exr", "--camera", partial)
        assert_clean_error(completed, EXIT_RUNTIME, "partial.json has no world_to_camera")
        assert not (tmp_path / "o.exr").exists()
    run_ok(hbao_tool, fixture_path("cycles_float_zip"), "-o", tmp_path / "n.exr", "--camera",
           partial, "--no-normals")
    flat = " ".join(str(v) for row in matrix for v in row)
    run_ok(hbao_tool, fixture_path("cycles_float_zip"), "-o", tmp_path / "m.exr", "--camera",
           partial, "--world-to-camera", flat)
    expected = tmp_path / "expected.exr"
    compute_ao(hbao_tool, "cycles_float_zip", expected)
    from hbao import exr_passes
    assert np.array_equal(exr_passes.read_channels(tmp_path / "m.exr", ["AO"])["AO"],
                          exr_passes.read_channels(expected, ["AO"])["AO"])
    no_camera = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", tmp_path / "w.exr")
    assert no_camera.returncode == 0 and "no world-to-camera matrix" in no_camera.stderr


@pytest.mark.parametrize("content, fragment", [
    ("{", "not valid JSON"),
    ('{"type": "PANO"}', '"type"'),
    ('{"lens": -1}', '"lens"'),
    ('{"world_to_camera": [[1, 0, 0, 0]]}', "world_to_camera"),
    ('{"world_to_camera": [[0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]]}',
     "world_to_camera\" is not a camera's matrix"),
    ('{"sensor_fit": 3}', "sensor_fit"),
    # cJSON took the first of a repeated key, Python's json and jq the last
    # (an exploratory run): the AO depended on the reader
    ('{"lens": 32, "sensor_width": 36, "lens": 80}', '"lens" is given more than once'),
    ('{"world_to_camera": null, "world_to_camera": null}', '"world_to_camera" is given more'),
])
def test_bad_camera_file_is_an_error(hbao_tool, tmp_path, content, fragment):
    bad = tmp_path / "camera.json"
    bad.write_text(content)
    completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", tmp_path / "o.exr",
                         "--camera", bad)
    assert_clean_error(completed, EXIT_RUNTIME, fragment)


# --- bad input files ---------------------------------------------------------

def test_corrupt_truncated_empty_and_missing_inputs(hbao_tool, tmp_path):
    data = fixture_path("cycles_float_zip").read_bytes()
    rng = random.Random(1)
    cases = {f"truncated_{n}.exr": data[:n] for n in (4, 100, 400, len(data) // 2, len(data) - 1)}
    cases["garbage.exr"] = bytes(rng.randrange(256) for _ in range(4096))
    cases["empty.exr"] = b""
    cases["text.exr"] = b"not an exr file\n"
    for file_name, content in cases.items():
        (tmp_path / file_name).write_bytes(content)
    cases["missing.exr"] = None
    for file_name in cases:
        output = tmp_path / f"out_{file_name}"
        for arguments in ([tmp_path / file_name, "-o", output], ["--info", tmp_path / file_name]):
            completed = run_tool(hbao_tool, *arguments)
            assert_clean_error(completed, EXIT_RUNTIME, str(tmp_path / file_name))
        assert not output.exists()
    assert leftover_temporary_files(tmp_path) == []


def test_an_input_that_is_a_folder_or_a_fifo_says_so_and_never_waits(hbao_tool, tmp_path):
    """--info on a FIFO waited for a writer forever (the AO refused it); a
    folder's message was OpenEXR's read error. Both modes now say what the
    path is; a camera file that is a folder says why it cannot be read."""
    folder = tmp_path / "folder.exr"
    folder.mkdir()
    fifo = tmp_path / "fifo.exr"
    os.mkfifo(fifo)
    for path, kind in ((folder, "a directory"), (fifo, "a FIFO")):
        for arguments in ([path, "-o", tmp_path / "out.exr"], ["--info", path]):
            completed = run_tool(hbao_tool, *arguments)
            assert_clean_error(completed, EXIT_RUNTIME, f"{path} is {kind}, not an EXR file")
    assert not (tmp_path / "out.exr").exists()
    camera = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", tmp_path / "out.exr",
                      "--camera", folder)
    assert_clean_error(camera, EXIT_RUNTIME, f"cannot read camera file {folder}: Is a directory")


def test_long_paths_keep_their_reason_and_say_which_path(hbao_tool, tmp_path):
    """A message about a 3000-byte path ends with its reason (1024 bytes of
    message cut it off), and a sequence's name past the system's limit says
    which flag's it is."""
    deep = tmp_path.joinpath(*(["d" * 200] * 15)) / "ao.exr"  # folders that do not exist
    completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", deep,
                         "--no-normals")
    assert completed.returncode == EXIT_RUNTIME, completed.stderr
    assert completed.stderr.rstrip().endswith(
        "does not exist (hbao makes no folders: make it first)"), completed.stderr
    for frame in (1, 2):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}.exr")
    pattern = str(tmp_path / ("p" * 200)) + "/" * 2000 + "x" * 1900 + "_#.png"
    sequence = run_tool(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "ao_#.exr",
                        "--preview", pattern, "--frames", "1-2", "--no-normals")
    assert_clean_error(sequence, EXIT_USAGE, "--preview of this frame would be 4096 bytes")


def test_fuzzed_inputs_never_crash(hbao_tool, tmp_path):
    """Random truncations and byte changes of every fixture, through
    scripts/fuzz_cli.sh (the one mutation loop): always exit 0, or 1 with a
    message, never a signal, a sanitizer report or a temporary file left.
    Uses the AddressSanitizer build when it exists (cmake -S . -B
    build-sanitize -DHBAO_SANITIZE=ON), else the normal one."""
    sanitized = REPO / "build-sanitize" / "hbao"
    tool = sanitized if sanitized.exists() else hbao_tool
    completed = subprocess.run([str(SCRIPTS / "fuzz_cli.sh"), str(FUZZ_CASES_PER_FIXTURE),
                                str(FUZZ_SEED)], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, errors="replace",
                               env=dict(os.environ, HBAO_TOOL=str(tool), TMPDIR=str(tmp_path)),
                               timeout=FUZZ_TIMEOUT_S)
    assert completed.returncode == 0, completed.stdout[-4000:]
    fixtures = len(list(FIXTURES.glob("*.exr")))
    # Two runs per case (compute and --info); the summary counts them all.
    assert f"{fixtures * FUZZ_CASES_PER_FIXTURE * 2} runs" in completed.stdout, completed.stdout


# --- never overwrite the input; atomic outputs --------------------------------

def test_output_equal_to_input_is_refused(hbao_tool, tmp_path):
    source = tmp_path / "in.exr"
    shutil.copyfile(fixture_path("cycles_float_zip"), source)
    original = source.read_bytes()
    (tmp_path / "hard.exr").hardlink_to(source)
    (tmp_path / "soft.exr").symlink_to(source)
    for target in (source, tmp_path / "." / "in.exr", tmp_path / "hard.exr",
                   tmp_path / "soft.exr"):
        for flag in ("-o", "--preview"):
            arguments = [source, "-o", tmp_path / "ok.exr", flag, target] if flag != "-o" \
                else [source, "-o", target]
            completed = run_tool(hbao_tool, *arguments)
            assert_clean_error(completed, EXIT_USAGE, "refusing to overwrite")
            assert source.read_bytes() == original
    assert not (tmp_path / "ok.exr").exists()


def test_one_pipe_named_twice_is_refused(hbao_tool, tmp_path):
    """-o /dev/stdout --preview /proc/self/fd/1: one pipe by two names, which
    would get the EXR and then the PNG. Refused; nothing reaches the pipe."""
    completed = subprocess.run(
        [str(hbao_tool), fixture_path("cycles_float_zip"), "-o", "/dev/stdout", "--preview",
         "/proc/self/fd/1", "--no-normals"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TOOL_TIMEOUT_S)
    assert completed.returncode == EXIT_USAGE, completed.stderr
    assert b"name the same file" in completed.stderr and completed.stdout == b""


def test_camera_file_is_never_an_output(hbao_tool, tmp_path):
    """The --camera file is an input too: -o or --preview naming it (by any
    name) is refused, and it keeps its contents."""
    camera = tmp_path / "camera.json"
    shutil.copyfile(camera_path("cycles_float_zip"), camera)
    original = camera.read_bytes()
    (tmp_path / "link.json").symlink_to(camera)
    for target in (camera, f"{tmp_path}/./camera.json", tmp_path / "link.json"):
        for flag in ("-o", "--preview"):
            outputs = ["-o", tmp_path / "ok.exr", flag, target] if flag != "-o" \
                else ["-o", target]
            completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), *outputs,
                                 "--camera", camera)
            assert_clean_error(completed, EXIT_USAGE, "is the --camera file")
            assert camera.read_bytes() == original
    assert sorted(p.name for p in tmp_path.iterdir()) == ["camera.json", "link.json"]


def test_output_and_preview_naming_one_file_are_refused(hbao_tool, tmp_path):
    """-o and --preview naming the same file by different names ("./",
    "sub/..", a link to the other): the PNG would replace the EXR. Refused
    before any work, nothing written, no temporary file left."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.png").symlink_to("ao.exr")
    # (strings: pathlib would drop the "./")
    for preview in (f"{tmp_path}/./ao.exr", f"{tmp_path}/sub/../ao.exr", tmp_path / "link.png"):
        completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o",
                             tmp_path / "ao.exr", "--preview", preview, "--no-normals")
        assert_clean_error(completed, EXIT_USAGE, "name the same file")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.png", "sub"]


def test_output_and_preview_through_a_bind_mount_are_one_file(hbao_tool, tmp_path):
    """-o a/ao.exr and --preview b/ao.exr where b is a bind mount of a (or
    one export mounted twice): realpath keeps the two names apart, and the
    PNG replaced the EXR, exit 0 (a review's find). The folders compared by
    device and inode: refused, nothing written. (A mount namespace of the
    test's own: needs root, as the test machines have.)"""
    first, second = tmp_path / "a", tmp_path / "b"
    first.mkdir()
    second.mkdir()
    script = (f'mount --bind "{first}" "{second}" && exec "{hbao_tool}" '
              f'"{fixture_path("cycles_float_zip")}" -o "{first}/ao.exr" '
              f'--preview "{second}/ao.exr" --no-normals')
    completed = subprocess.run(["unshare", "--mount", "sh", "-c", script], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, timeout=TOOL_TIMEOUT_S)
    assert_clean_error(completed, EXIT_USAGE, "name the same file")
    assert list(first.iterdir()) == [] and list(second.iterdir()) == []


def test_a_preview_device_that_fails_leaves_the_output_as_it_was(hbao_tool, tmp_path):
    """--preview /dev/full: a device's data is copied at the end, and the
    copy fails (no space). -o was renamed into place first, so the run
    failed with the output replaced (a review's find); a device's or FIFO's
    destination is now written first, and its failure leaves -o as it was
    and no temporary file."""
    output = tmp_path / "ao.exr"
    output.write_bytes(b"previous result")
    completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", output,
                         "--preview", "/dev/full", "--no-normals")
    assert_clean_error(completed, EXIT_RUNTIME, "/dev/full")
    assert output.read_bytes() == b"previous result"
    assert leftover_temporary_files(tmp_path) == []


def test_existing_output_is_replaced_only_on_success(hbao_tool, tmp_path):
    output = tmp_path / "ao.exr"
    preview = tmp_path / "ao.png"
    output.write_bytes(b"previous result")
    preview.write_bytes(b"previous preview")
    truncated = tmp_path / "truncated.exr"
    truncated.write_bytes(fixture_path("cycles_float_zip").read_bytes()[:2000])
    for source in (truncated, tmp_path / "missing.exr", fixture_path("no_depth")):
        completed = run_tool(hbao_tool, source, "-o", output, "--preview", preview)
        assert completed.returncode == EXIT_RUNTIME
        assert output.read_bytes() == b"previous result"
        assert preview.read_bytes() == b"previous preview"
    compute_ao(hbao_tool, "cycles_float_zip", output, "--preview", preview)
    description = info(hbao_tool, output)
    assert [c["name"] for c in description["channels"]] == ["AO"]
    assert png_header(preview) == (description["width"], description["height"], 8, 0)
    assert leftover_temporary_files(tmp_path) == []


def test_symbolic_link_output_replaces_its_target_and_keeps_the_link(hbao_tool, tmp_path):
    """A link is followed, as a shell's `>` would: the target gets the image
    (atomically), the link stays a link; a dangling link creates its target."""
    reference = tmp_path / "reference.exr"
    compute_ao(hbao_tool, "cycles_float_zip", reference)
    (tmp_path / "real").mkdir()
    target = tmp_path / "real" / "target.exr"
    target.write_bytes(b"previous result")
    links = {tmp_path / "link.exr": Path("real") / "target.exr",
             tmp_path / "dangling.exr": Path("real") / "new.exr"}
    for link, points_to in links.items():
        link.symlink_to(points_to)
        compute_ao(hbao_tool, "cycles_float_zip", link)
        assert link.is_symlink() and os.readlink(link) == str(points_to)
        assert (tmp_path / points_to).read_bytes() == reference.read_bytes()
    assert leftover_temporary_files(tmp_path) == []
    assert leftover_temporary_files(tmp_path / "real") == []


def test_fifo_output_is_written_through(hbao_tool, tmp_path):
    """A FIFO is not replaced by a file: its reader gets the whole EXR."""
    reference = tmp_path / "reference.exr"
    compute_ao(hbao_tool, "cycles_float_zip", reference)
    fifo = tmp_path / "pipe.exr"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_bytes()))
    reader.start()
    compute_ao(hbao_tool, "cycles_float_zip", fifo)
    reader.join(TOOL_TIMEOUT_S)
    assert received == [reference.read_bytes()]
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert leftover_temporary_files(tmp_path) == []


def test_a_pipe_closed_by_its_reader_is_a_write_error(hbao_tool, tmp_path):
    """hbao ... -o /dev/stdout | head: the write fails with EPIPE (SIGPIPE is
    ignored), so the run ends with its message and exit 1 and removes the
    preview's temporary file, instead of dying of the signal mid-write."""
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader is gone before the first byte
    with os.fdopen(write_end, "wb") as pipe:
        completed = subprocess.run(
            [str(hbao_tool), fixture_path("cycles_float_zip"), "-o", "/dev/stdout",
             "--no-normals", "--preview", tmp_path / "ao.png"],
            stdout=pipe, stderr=subprocess.PIPE, text=True, timeout=TOOL_TIMEOUT_S)
    assert_clean_error(completed, EXIT_RUNTIME, "cannot write /dev/stdout", "Broken pipe")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("arguments", [
    ["--help"], ["--version"], ["--info", "FIXTURE"], ["--info", "FIXTURE", "--json"]])
def test_text_for_a_reader_that_left_ends_quietly(hbao_tool, arguments):
    """hbao --help | head: the reader has what it wanted, so text for a person
    (help, version, --info) ends with exit 0 and nothing on stderr, even when
    the reader left before the first byte (EPIPE on every write)."""
    arguments = [fixture_path("cycles_float_zip") if a == "FIXTURE" else a for a in arguments]
    read_end, write_end = os.pipe()
    os.close(read_end)
    with os.fdopen(write_end, "wb") as pipe:
        completed = subprocess.run([str(hbao_tool), *arguments], stdout=pipe,
                                   stderr=subprocess.PIPE, text=True, timeout=TOOL_TIMEOUT_S)
    assert (completed.returncode, completed.stderr) == (0, "")


def test_a_preview_on_a_full_disk_says_why(hbao_tool, tmp_path):
    """The preview's write fails with ENOSPC on a full file system (a tmpfs
    of two pages, filled): its message gives the reason, as the EXR's does,
    nothing is committed and no temporary file is left."""
    with small_tmpfs(tmp_path / "full", "8k") as folder:
        (folder / "filler").write_bytes(b"x" * 8192)
        completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o",
                             tmp_path / "ao.exr", "--preview", folder / "ao.png", "--no-normals")
        assert_clean_error(completed, EXIT_RUNTIME, "ao.png", "No space left on device")
        assert not (tmp_path / "ao.exr").exists()
        assert sorted(p.name for p in folder.iterdir()) == ["filler"]


def test_character_device_output_is_written_through(hbao_tool, tmp_path):
    """As root, a replaced /dev/null would break the system (issue 13, D3)."""
    before = os.lstat("/dev/null")
    compute_ao(hbao_tool, "cycles_float_zip", "/dev/null")
    after = os.lstat("/dev/null")
    assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev
    assert leftover_temporary_files("/dev") == []


def test_block_device_socket_and_directory_outputs_are_refused(hbao_tool, tmp_path):
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(str(tmp_path / "socket.exr"))
    targets = {tmp_path / "socket.exr": "socket", tmp_path: "directory"}
    if os.geteuid() == 0:
        # A device node of the loop driver (major 7); nothing opens it.
        os.mknod(tmp_path / "block.exr", 0o600 | stat.S_IFBLK, os.makedev(7, 200))
        targets[tmp_path / "block.exr"] = "block device"
    try:
        for target, kind in targets.items():
            for flag in ("-o", "--preview"):
                arguments = [fixture_path("cycles_float_zip"), "-o", tmp_path / "ok.exr",
                             flag, target] if flag != "-o" else \
                    [fixture_path("cycles_float_zip"), "-o", target]
                completed = run_tool(hbao_tool, *arguments)
                assert_clean_error(completed, EXIT_USAGE, str(target), kind)
        assert stat.S_ISSOCK(os.lstat(tmp_path / "socket.exr").st_mode)
        if os.geteuid() == 0:
            assert stat.S_ISBLK(os.lstat(tmp_path / "block.exr").st_mode)
    finally:
        server.close()
    assert not (tmp_path / "ok.exr").exists() and leftover_temporary_files(tmp_path) == []


def test_an_output_in_no_folder_says_what_is_wrong(hbao_tool, tmp_path):
    """`-o new.exr/` (a trailing '/') and `-o missing/ao.exr` were both
    "cannot create a file next to ...: No such file or directory", which
    names neither the stray '/' nor the folder (a review's find). Now each
    says what is wrong, before any work, and nothing is made."""
    (tmp_path / "plain").write_bytes(b"a file")
    cases = [
        (["-o", f"{tmp_path}/new.exr/"], EXIT_USAGE,
         [f"{tmp_path}/new.exr/ ends in '/', so it names a folder, not a file"]),
        (["-o", tmp_path / "ok.exr", "--preview", f"{tmp_path}/p.png/"], EXIT_USAGE,
         [f"{tmp_path}/p.png/ ends in '/'"]),
        (["-o", tmp_path / "missing" / "ao.exr"], EXIT_RUNTIME,
         [f"its folder {tmp_path}/missing does not exist", "make it first"]),
        (["-o", tmp_path / "plain" / "ao.exr"], EXIT_RUNTIME,
         [f"path {tmp_path}/plain is not a folder"]),
    ]
    for arguments, status, fragments in cases:
        completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), *arguments)
        assert_clean_error(completed, status, *fragments)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain"]


def test_longest_legal_output_name_works(hbao_tool, tmp_path):
    """NAME_MAX (255 bytes) is the file system's limit on one name; the
    temporary name must not push a legal name over it (issue 13, D5)."""
    name_max = os.pathconf(tmp_path, "PC_NAME_MAX")
    output = tmp_path / ("a" * (name_max - len(".exr")) + ".exr")
    preview = tmp_path / ("p" * (name_max - len(".png")) + ".png")
    compute_ao(hbao_tool, "cycles_float_zip", output, "--preview", preview)
    assert [c["name"] for c in info(hbao_tool, output)["channels"]] == ["AO"]
    assert png_header(preview)[:2] == (64, 48)


# The slow run for the signal test: 512x512 pixels, 64 directions x 64 steps
# on one thread take about 1 s on this project's machine, far longer than the
# few milliseconds between the temporary file appearing and the signal.
SLOW_SIZE = 512
SLOW_RUN = ["--directions", "64", "--steps", "64", "--threads", "1"]


def slow_input(path):
    y, x = np.mgrid[0:SLOW_SIZE, 0:SLOW_SIZE].astype(np.float32)
    path.write_bytes(scanline_exr({"Depth.Z": 5.0 + 0.01 * x + np.sin(y / 7.0)},
                                  SLOW_SIZE, SLOW_SIZE))


# The signals after which the tool removes its temporary files.
CLEANUP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def default_signal_actions():
    """For the tool's process: the suite may itself run with some of these
    signals ignored (under `nohup`, or started with `&` by a script), and the
    tool leaves an ignored signal ignored (test below)."""
    for number in CLEANUP_SIGNALS:
        signal.signal(number, signal.SIG_DFL)


def ignore_hangup():
    default_signal_actions()
    signal.signal(signal.SIGHUP, signal.SIG_IGN)


def open_temporary_files(pid, folder):
    """The temporary files process `pid` holds in `folder`: named ones
    (.hbao-tmp-), and unnamed ones (O_TMPFILE: "folder/#123 (deleted)")."""
    found = 0
    for entry in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(entry)
        except OSError:  # closed meanwhile
            continue
        if target.startswith(f"{folder}/") and (
                ".hbao-tmp-" in target or target.startswith(f"{folder}/#")):
            found += 1
    return found


# HBAO_TMPFILE=0: named temporary files (.hbao-tmp-), which the tool removes
# when a signal ends it; by default they are unnamed until their rename
# (O_TMPFILE), so that no kill leaves one.
TEMPORARY_KINDS = {"unnamed": None, "named": {"HBAO_TMPFILE": "0"}}


@pytest.mark.parametrize("tmpfile", ["0", "1"])
def test_named_temporaries_a_killed_run_left_are_removed(hbao_tool, tmp_path, tmpfile):
    """Where the file system has no O_TMPFILE (NFS before 4.2; HBAO_TMPFILE=0
    here), SIGKILL leaves the run's named temporary in the output's folder,
    up to a frame's size, and a farm rerunning the task piled them up (an
    exploratory run). A run removes, before its first temporary there, those
    of its user that nothing wrote for a day, and says so; a fresh one (a run
    still computing: its temporary is written after its frame is computed),
    one 23 hours old (a task the farm suspended), another name and a
    symbolic link stay. A run whose own temporaries are unnamed (O_TMPFILE)
    sweeps too: a farm's nodes may mount the folder by NFS versions with and
    without it (a README audit found such a run left them)."""
    out = tmp_path / "out"
    out.mkdir()
    stale = out / ".hbao-tmp-a1B2c3"
    stale.write_bytes(b"\0" * 4096)
    day_ago, suspended = time.time() - 25 * 3600, time.time() - 23 * 3600
    os.utime(stale, (day_ago, day_ago))
    kept = {name: out / name for name in (".hbao-tmp-z9Y8x7", ".hbao-tmp-SuSp3d",
                                          ".hbao-tmp-long-name", ".hbao-tmp-L1nk00")}
    kept[".hbao-tmp-z9Y8x7"].write_bytes(b"fresh")
    kept[".hbao-tmp-SuSp3d"].write_bytes(b"suspended")
    os.utime(kept[".hbao-tmp-SuSp3d"], (suspended, suspended))
    kept[".hbao-tmp-long-name"].write_bytes(b"other")
    os.utime(kept[".hbao-tmp-long-name"], (day_ago, day_ago))
    kept[".hbao-tmp-L1nk00"].symlink_to(kept[".hbao-tmp-long-name"])
    os.utime(kept[".hbao-tmp-L1nk00"], (day_ago, day_ago), follow_symlinks=False)
    completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", out / "ao.exr",
                         env=dict(os.environ, HBAO_TMPFILE=tmpfile))
    assert completed.returncode == 0, completed.stderr
    assert "removed 1 temporary file (.hbao-tmp-*) that a killed run left" in completed.stderr
    assert not stale.exists() and all(os.path.lexists(path) for path in kept.values())
    assert sorted(p.name for p in out.iterdir()) == sorted(["ao.exr", *kept])


def signal_during_run(command, outputs, temporaries, signal_number, preexec_fn, env=None):
    """Starts the tool, waits until it holds its `temporaries` temporary
    files (so that the signal falls inside the run), sends the signal and
    returns the finished process."""
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               preexec_fn=preexec_fn,
                               env=None if env is None else dict(os.environ, **env))
    try:
        deadline = time.monotonic() + TOOL_TIMEOUT_S
        while open_temporary_files(process.pid, outputs) < temporaries \
                and process.poll() is None:
            assert time.monotonic() < deadline
            time.sleep(0.005)
        # All temporary files existed while the tool was still running:
        # otherwise the signal below would test nothing.
        assert process.poll() is None, "the run ended before it could be interrupted"
        process.send_signal(signal_number)
        process.wait(TOOL_TIMEOUT_S)
    finally:
        process.kill()
        process.wait()
    return process


@pytest.mark.parametrize("signal_number, frames, kind", [
    (number, frames, kind) for kind in TEMPORARY_KINDS
    # Two frames at once (--jobs 2): four temporary files, from two threads.
    for number, frames in ((signal.SIGINT, 1), (signal.SIGTERM, 1), (signal.SIGHUP, 1),
                           (signal.SIGTERM, 2))] + [
    # No handler runs: only unnamed temporary files leave nothing (a farm's
    # hard kill, the out-of-memory killer); a named one outlives it.
    (signal.SIGKILL, 2, "unnamed")])
def test_signal_removes_the_temporary_files(hbao_tool, tmp_path, signal_number, frames, kind):
    outputs = tmp_path / "out"
    outputs.mkdir()
    if frames == 1:
        slow_input(tmp_path / "big.exr")
        command = [str(hbao_tool), str(tmp_path / "big.exr"), "-o", str(outputs / "ao.exr"),
                   "--preview", str(outputs / "ao.png")] + SLOW_RUN
    else:
        for frame in range(1, frames + 1):
            slow_input(tmp_path / f"big_{frame}.exr")
        command = [str(hbao_tool), str(tmp_path / "big_#.exr"), "-o", str(outputs / "ao_#.exr"),
                   "--preview", str(outputs / "ao_#.png"), "--frames", f"1-{frames}",
                   "--jobs", str(frames)] + SLOW_RUN
    process = signal_during_run(command, outputs, 2 * frames, signal_number,
                                default_signal_actions, TEMPORARY_KINDS[kind])
    # The exit status says the signal ended the run.
    assert process.returncode == -signal_number, process.stderr.read()
    assert list(outputs.iterdir()) == []


@pytest.mark.parametrize("kind", TEMPORARY_KINDS)
def test_a_sequence_interrupted_at_any_moment_leaves_no_temporary_file(hbao_tool, tmp_path,
                                                                       kind):
    """Interrupted at random moments, a sequence of small frames on two
    workers (a temporary made, named or renamed at nearly every moment):
    the signal's cleanup once ran in the main thread while a worker made
    or named a temporary, which then stayed, a frame's whole file (2 to 10
    of 150 interrupted runs in a review; 4-6 of 200 before the fix, 0 of
    600 after, session 70). 100 interruptions, SIGINT and SIGTERM by
    turns, each within 20 ms of the start: none leaves a temporary, and
    each ends by its signal."""
    runs = 100
    for frame in range(1, 9):
        shutil.copyfile(fixture_path("cycles_float_none"), tmp_path / f"r_{frame}.exr")
    outputs = tmp_path / "out"
    rng = np.random.default_rng(70)
    left = []
    for run in range(runs):
        shutil.rmtree(outputs, ignore_errors=True)
        outputs.mkdir()
        number = (signal.SIGINT, signal.SIGTERM)[run % 2]
        process = subprocess.Popen(
            [str(hbao_tool), str(tmp_path / "r_#.exr"), "-o", str(outputs / "ao_#.exr"),
             "--preview", str(outputs / "ao_#.png"), "--frames", "1-8", "-j", "2",
             "--no-normals"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=default_signal_actions,
            env=None if TEMPORARY_KINDS[kind] is None else dict(os.environ,
                                                                **TEMPORARY_KINDS[kind]))
        try:
            time.sleep(rng.uniform(0.0, 0.02))
            process.send_signal(number)
            process.wait(TOOL_TIMEOUT_S)
        finally:
            process.kill()
            process.wait()
        # (a run that ended before the signal: 0)
        assert process.returncode in (0, -number), (run, process.returncode)
        left += [(run, p.name) for p in outputs.iterdir() if p.name.startswith(".hbao-tmp-")]
    assert left == []


def test_an_ignored_hangup_stays_ignored(hbao_tool, tmp_path):
    """Started under nohup (SIGHUP ignored), the tool is not ended by a hangup:
    it finishes and writes its outputs, and leaves no temporary file."""
    outputs = tmp_path / "out"
    outputs.mkdir()
    slow_input(tmp_path / "big.exr")
    command = [str(hbao_tool), str(tmp_path / "big.exr"), "-o", str(outputs / "ao.exr"),
               "--preview", str(outputs / "ao.png")] + SLOW_RUN
    process = signal_during_run(command, outputs, 2, signal.SIGHUP, ignore_hangup)
    assert process.returncode == 0, process.stderr.read()
    assert sorted(p.name for p in outputs.iterdir()) == ["ao.exr", "ao.png"]


def test_size_claim_is_checked_against_the_file_before_allocating(hbao_tool, tmp_path):
    """A ~500-byte header claiming 65536x65536 pixels (16 GiB per float
    channel) is refused for what the file holds, not by a failed allocation:
    the address space is limited to 1 GiB, so a reservation for the claimed
    size fails ("out of memory") instead of silently succeeding through
    overcommit (issue 13, D6)."""
    claim = tmp_path / "claim.exr"
    claim.write_bytes(scanline_exr({"Depth.Z": None}, 0, 0, claimed_size=(65536, 65536)))
    address_space = 1 << 30

    def limit_memory():
        resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))

    for arguments in ([claim, "-o", tmp_path / "ao.exr"], ["--info", claim]):
        completed = subprocess.run([str(hbao_tool)] + [str(a) for a in arguments],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                   timeout=TOOL_TIMEOUT_S, preexec_fn=limit_memory)
        assert_clean_error(completed, EXIT_RUNTIME, "claims a 65536x65536 image")
        assert "out of memory" not in completed.stderr
    assert not (tmp_path / "ao.exr").exists() and leftover_temporary_files(tmp_path) == []


def test_out_of_memory_names_the_file_and_the_stage(hbao_tool, tmp_path):
    """Short of memory for the passes (a 2000x1500 render's Depth and
    Normal take 60 MB; the address space is limited to 50 MB, which the
    tool alone fits in), the message names the file, what was being done
    and how much it needed: a farm's log of many frames says which."""
    render = tmp_path / "render.exr"
    depth = np.full((1500, 2000), 5.0, np.float32)
    normal = np.zeros_like(depth)
    render.write_bytes(scanline_exr({"ViewLayer.Depth.Z": depth, "ViewLayer.Normal.X": normal,
                                     "ViewLayer.Normal.Y": normal,
                                     "ViewLayer.Normal.Z": normal + 1.0}, 2000, 1500))
    address_space = 50 << 20

    def limit_memory():
        resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))

    completed = subprocess.run([str(hbao_tool), str(render), "-o", str(tmp_path / "ao.exr")],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               timeout=TOOL_TIMEOUT_S, preexec_fn=limit_memory)
    assert_clean_error(completed, EXIT_RUNTIME, f"{render}: out of memory reading the passes of "
                       "a 2000x1500 image (60 MB)")
    assert not (tmp_path / "ao.exr").exists() and leftover_temporary_files(tmp_path) == []


def test_unwritable_output_folder_is_an_error(hbao_tool, tmp_path):
    completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o",
                         tmp_path / "no_such_folder" / "ao.exr")
    assert_clean_error(completed, EXIT_RUNTIME, "no_such_folder")


def run_with_closed(tool, closing, *arguments):
    """The tool started with some standard descriptors closed (`closing`:
    bash redirections such as ">&-")."""
    script = 'exec "$0" "$@" ' + closing
    return subprocess.run(["bash", "-c", script, str(tool)] + [str(a) for a in arguments],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                          timeout=TOOL_TIMEOUT_S)


def test_closed_standard_descriptors_are_never_the_tools_files(hbao_tool, tmp_path):
    """A caller that closed stdout (`>&-`): the input, opened first, would
    take descriptor 1, and -o /dev/stdout named the input, which the AO then
    replaced. With all three closed, the temporary outputs took 1 and 2 and
    the tool's warning and progress lines went into them. Each closed one is
    /dev/null now: the input is kept and the outputs are a normal run's."""
    source = tmp_path / "render.exr"
    shutil.copyfile(fixture_path("cycles_float_zip"), source)
    before = source.read_bytes()
    camera = camera_path("cycles_float_zip")
    for closing in (">&-", "2>&- >&-"):
        completed = run_with_closed(hbao_tool, closing, source, "-o", "/dev/stdout",
                                    "--camera", camera)
        assert completed.returncode == 0 and source.read_bytes() == before, closing
    # a warning (normals without a camera matrix) and a sequence's progress
    expected = tmp_path / "expected"
    expected.mkdir()
    run_ok(hbao_tool, source, "-o", expected / "a.exr", "--preview", expected / "a.png")
    folder = tmp_path / "closed"
    folder.mkdir()
    for frame in (1, 2, 3):
        shutil.copyfile(source, folder / f"render_{frame}.exr")
    closed = run_with_closed(hbao_tool, "<&- >&- 2>&-", folder / "render_#.exr", "-o",
                             folder / "ao_#.exr", "--preview", folder / "ao_#.png",
                             "--frames", "1-3", "--jobs", "2")
    assert closed.returncode == 0
    for frame in (1, 2, 3):
        assert (folder / f"ao_{frame}.exr").read_bytes() == (expected / "a.exr").read_bytes()
        assert (folder / f"ao_{frame}.png").read_bytes() == (expected / "a.png").read_bytes()
    assert source.read_bytes() == before


def test_the_tool_runs_from_a_workers_folder_and_an_install_prefix(hbao_tool, tmp_path):
    """A render farm worker gets hbao and libhbao.so.0 in one folder, or a
    `cmake --install` prefix: the tool finds its library there ($ORIGIN),
    from any working directory, and never in the working directory itself
    (an empty RUNPATH entry would read as ".")."""
    runpath = subprocess.run(["readelf", "-d", str(hbao_tool)], stdout=subprocess.PIPE,
                             text=True, check=True).stdout
    entries = [line.split("[", 1)[1].rstrip("]").split(":") for line in runpath.splitlines()
               if "RUNPATH" in line or "RPATH" in line]
    assert entries and "" not in entries[0] and entries[0][0] == "$ORIGIN", runpath
    worker = tmp_path / "worker"
    worker.mkdir()
    shutil.copyfile(hbao_tool, worker / "hbao")
    (worker / "hbao").chmod(0o755)
    shutil.copyfile(hbao_tool.parent / "libhbao.so.0", worker / "libhbao.so.0")
    prefix = tmp_path / "prefix"
    installed = subprocess.run(["cmake", "--install", str(hbao_tool.parent), "--prefix",
                                str(prefix)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True)
    assert installed.returncode == 0, installed.stdout
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    expected = tmp_path / "built.exr"
    compute_ao(hbao_tool, "cycles_float_zip", expected)
    for place, tool in (("worker", worker / "hbao"), ("prefix", prefix / "bin" / "hbao")):
        output = tmp_path / f"{place}.exr"
        completed = subprocess.run(
            [str(tool), str(fixture_path("cycles_float_zip")), "-o", str(output), "--camera",
             str(camera_path("cycles_float_zip"))], cwd=elsewhere, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True, timeout=TOOL_TIMEOUT_S,
            env={k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"})
        assert completed.returncode == 0, completed.stderr
        assert output.read_bytes() == expected.read_bytes()


# --- sequences -------------------------------------------------------------------

def sequence_folder(tmp_path):
    """Frames 1, 2, 4 are fixtures, 3 is truncated, 5 is missing."""
    folder = tmp_path / "sequence"
    folder.mkdir()
    sources = {1: "cycles_float_zip", 2: "eevee_half", 4: "ortho_float"}
    for frame, name in sources.items():
        shutil.copyfile(fixture_path(name), folder / f"render_{frame:04d}.exr")
    (folder / "render_0003.exr").write_bytes(fixture_path("cycles_float_zip").read_bytes()[:3000])
    return folder, sources


def run_sequence(tool, folder, *extra):
    return run_tool(tool, folder / "render_####.exr", "-o", folder / "ao_####.exr",
                    "--preview", folder / "ao_####.png", "--frames", "1-5", "--no-normals",
                    *extra)


def test_sequence_computes_every_frame_and_lists_the_failed_ones(hbao_tool, tmp_path):
    folder, sources = sequence_folder(tmp_path)
    completed = run_sequence(hbao_tool, folder, "--jobs", "2")
    assert_clean_error(completed, EXIT_RUNTIME, "2 of 5 frames failed: 3, 5")
    # frame 5, with no input, fails before the others run, in one line; the
    # progress counts the four that run
    assert "no input for 1 of the 5 frames (5; the first, " in completed.stderr
    progress = [line for line in completed.stderr.splitlines() if line.startswith("hbao: [")]
    assert len(progress) == 4 and all(f"[{k}/4]" in progress[k - 1] for k in range(1, 5))
    assert sum("failed" in line for line in progress) == 1
    # Each frame's output is what a single run on that frame writes, byte for
    # byte (the library's result does not depend on the thread count).
    for frame, name in sources.items():
        single = tmp_path / f"single_{frame}.exr"
        run_ok(hbao_tool, fixture_path(name), "-o", single, "--no-normals")
        assert (folder / f"ao_{frame:04d}.exr").read_bytes() == single.read_bytes()
        assert png_header(folder / f"ao_{frame:04d}.png")[2:] == (8, 0)
    for frame in (3, 5):
        assert not (folder / f"ao_{frame:04d}.exr").exists()
        assert not (folder / f"ao_{frame:04d}.png").exists()
    assert leftover_temporary_files(folder) == []


def test_a_mistyped_frame_range_fails_its_missing_frames_at_once(hbao_tool, tmp_path):
    """--frames 0-1048574 (Blender's every frame) over five renders ran a
    million frames that failed one by one, a line each, for some 20 s: the
    frames with no input now fail before the run, in one line of ranges, and
    the summary gives ranges too. Where no listed frame has its input, that
    is the error, and nothing runs."""
    folder, sources = sequence_folder(tmp_path)
    completed = run_tool(hbao_tool, folder / "render_####.exr", "-o", folder / "ao_####.exr",
                         "--frames", "0-1048574", "--no-normals", "-j", "2")
    assert_clean_error(completed, EXIT_RUNTIME,
                       "1048572 of 1048575 frames failed: 0, 3, 5-1048574")
    assert "no input for 1048571 of the 1048575 frames (0, 5-1048574; the first, " \
        in completed.stderr
    assert len(completed.stderr.splitlines()) == 6, completed.stderr  # warning, 4 frames, error
    for frame in sources:
        assert (folder / f"ao_{frame:04d}.exr").exists()
    nothing = run_tool(hbao_tool, folder / "typo_####.exr", "-o", folder / "t_####.exr",
                       "--frames", "1-250")
    assert_clean_error(nothing, EXIT_RUNTIME, "no input for any of the 250 listed frames",
                       "typo_0001.exr: No such file or directory")
    assert len(nothing.stderr.splitlines()) == 1 and not list(folder.glob("t_*"))


def test_an_output_reaching_a_frame_without_input_is_refused(hbao_tool, tmp_path):
    """A frame with no input is left out of the up-front checks' reads of
    inputs, but its output that exists still counts: frame 1's output
    reaching frame 2's through a folder's link (frame 2's render not there
    yet) put frame 1's AO in frame 2's file, exit 1 for frame 2 alone (a
    review of 7e7c494, which left such frames out whole)."""
    shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / "r_1.exr")
    (tmp_path / "d2").mkdir()
    (tmp_path / "d2" / "ao.exr").write_bytes(b"frame 2's earlier output")
    (tmp_path / "d1").symlink_to("d2")
    # names relative to the folder, which the names' checks do not match
    # with the link's resolved path: only the file's identity tells
    completed = subprocess.run([str(hbao_tool), "r_#.exr", "-o", "d#/ao.exr", "--frames", "1-2",
                                "--no-normals"], cwd=tmp_path, capture_output=True, text=True,
                               timeout=TOOL_TIMEOUT_S)
    assert_clean_error(completed, EXIT_USAGE, "-o of frame 1", "is the -o of frame 2 by another")
    assert (tmp_path / "d2" / "ao.exr").read_bytes() == b"frame 2's earlier output"


def test_an_input_dated_ahead_of_the_clock_is_computed_once(hbao_tool, tmp_path):
    """A render (or camera file) whose time lies ahead of this machine's
    clock (a render node whose clock is ahead, over NFS) left every output
    older than its input, so each rerun recomputed every frame. An output whose seal names the
    input as it is now is up to date; one without a seal is still redone
    (nothing then says it was computed from that input), and so is one
    whose input changed since (its time or size)."""
    folder, sources = sequence_folder(tmp_path)
    ahead = time.time_ns() + 3600 * 10**9
    for frame in sources:
        os.utime(folder / f"render_{frame:04d}.exr", ns=(ahead, ahead))
    run_sequence(hbao_tool, folder)
    assert all(os.stat(folder / f"ao_{f:04d}.exr").st_mtime_ns < ahead for f in sources)
    written = {f: os.stat(folder / f"ao_{f:04d}.exr").st_mtime_ns for f in sources}
    again = run_sequence(hbao_tool, folder)
    assert again.stderr.count("is up to date, skipped") == 3, again.stderr
    assert {f: os.stat(folder / f"ao_{f:04d}.exr").st_mtime_ns for f in sources} == written
    # a camera file counts by what it holds, not by its time: dated ahead
    # too (as the render node that exported it), or written again with the
    # same values, it redid every frame
    camera = tmp_path / "cam.json"
    shutil.copyfile(FIXTURES / "cycles_float_zip.camera.json", camera)
    run_sequence(hbao_tool, folder, "--camera", camera)
    os.utime(camera, ns=(ahead, ahead))
    dated = run_sequence(hbao_tool, folder, "--camera", camera)
    assert dated.stderr.count("is up to date, skipped") == 3, dated.stderr
    camera.write_text(camera.read_text())
    rewritten = run_sequence(hbao_tool, folder, "--camera", camera)
    assert rewritten.stderr.count("is up to date, skipped") == 3, rewritten.stderr
    run_sequence(hbao_tool, folder)
    os.removexattr(folder / "ao_0001.exr", SEAL)
    later = ahead + 10**9
    os.utime(folder / "render_0002.exr", ns=(later, later))
    redone = run_sequence(hbao_tool, folder)
    assert redone.stderr.count("is up to date, skipped") == 1, redone.stderr
    assert "frame 1: " in redone.stderr and "frame 2: " in redone.stderr
    for frame, name in sources.items():
        single = tmp_path / f"single_{frame}.exr"
        run_ok(hbao_tool, fixture_path(name), "-o", single, "--no-normals")
        assert (folder / f"ao_{frame:04d}.exr").read_bytes() == single.read_bytes()


def test_sequence_skips_up_to_date_frames(hbao_tool, tmp_path):
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    written = {frame: os.stat(folder / f"ao_{frame:04d}.exr").st_mtime_ns for frame in sources}
    again = run_sequence(hbao_tool, folder)
    assert again.returncode == EXIT_RUNTIME  # frames 3 and 5 still fail
    assert again.stderr.count("is up to date, skipped") == 3
    assert {f: os.stat(folder / f"ao_{f:04d}.exr").st_mtime_ns for f in sources} == written
    # A newer input makes its frame out of date; --force redoes them all.
    later = written[2] + 10**9
    os.utime(folder / "render_0002.exr", ns=(later, later))
    touched = run_sequence(hbao_tool, folder)
    assert touched.stderr.count("is up to date, skipped") == 2
    assert "frame 2: " in touched.stderr and os.stat(folder / "ao_0002.exr").st_mtime_ns != \
        written[2]
    forced = run_sequence(hbao_tool, folder, "--force")
    assert "is up to date" not in forced.stderr
    assert leftover_temporary_files(folder) == []


def test_sequence_redoes_frames_computed_with_other_flags(hbao_tool, tmp_path):
    """An output newer than its input is up to date only if its header holds
    the settings this run would write (hbaoSettings): a farm task rerun with
    another radius recomputes every frame, then skips them with the same
    flags; an output without the attribute (another tool's file) is redone."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    changed = run_sequence(hbao_tool, folder, "--radius", "0.5")
    assert "is up to date" not in changed.stderr
    for frame in sources:
        single = tmp_path / f"single_{frame}.exr"
        run_ok(hbao_tool, fixture_path(sources[frame]), "-o", single, "--no-normals",
               "--radius", "0.5")
        assert (folder / f"ao_{frame:04d}.exr").read_bytes() == single.read_bytes()
    same = run_sequence(hbao_tool, folder, "--radius", "0.5", "--threads", "1")
    assert same.stderr.count("is up to date, skipped") == 3  # threads change no value
    foreign = folder / "ao_0001.exr"  # newer, no hbaoSettings (not a render: no Depth)
    foreign.write_bytes(scanline_exr({"AO": np.ones((4, 4), np.float32)}, 4, 4))
    redone = run_sequence(hbao_tool, folder, "--radius", "0.5")
    assert redone.stderr.count("is up to date, skipped") == 2
    assert "frame 1: " in redone.stderr and b"hbaoSettings" in foreign.read_bytes()


def test_sequence_flags_that_say_the_same_in_other_words_skip_frames(hbao_tool, tmp_path):
    """The stamp holds what the AO was computed with, not the flags as typed:
    a farm rerun that adds --layer naming the file's only layer, gives as
    flags what the camera file or the header already says, or a blur size or
    sharpness that computes the same, recomputed every frame. It now skips
    them; a flag that changes a value still recomputes, and writes what a
    single run writes."""
    name = "cycles_float_zip"
    for frame in (1, 2):
        shutil.copyfile(fixture_path(name), tmp_path / f"r_{frame}.exr")
    camera = json.loads(camera_path(name).read_text())

    def run(*extra):
        return run_ok(hbao_tool, tmp_path / "r_#.exr", "-o", tmp_path / "ao_#.exr",
                      "--frames", "1-2", "--camera", camera_path(name), *extra).stderr

    run()
    for same in (["--layer", "ViewLayer"], ["--camera-type", camera["type"]],
                 ["--lens", str(camera["lens"]), "--sensor-width", str(camera["sensor_width"])],
                 ["--pixel-aspect-x", "1", "--pixel-aspect-y", "1"]):  # the header's
        stderr = run(*same)
        assert stderr.count("is up to date, skipped") == 2, (same, stderr)
    assert "is up to date" not in run("--no-normals")  # another computation
    assert run("--layer", "ViewLayer", "--no-normals").count("is up to date, skipped") == 2
    # the blur as its kernel (hbao_params_resolve): an even size rounds down
    # (6 is the default 5), and 0 to 2 are no blur, whose sharpness does nothing
    assert run("--no-normals", "--blur", "6").count("is up to date, skipped") == 2
    assert "is up to date" not in run("--no-normals", "--blur", "0")
    for same in (["--blur", "1"], ["--blur", "2", "--blur-sharpness", "8"],
                 ["--blur", "0", "--blur-sharpness", "5000"]):
        stderr = run("--no-normals", *same)
        assert stderr.count("is up to date, skipped") == 2, (same, stderr)
        assert "limit" not in stderr, stderr  # no warning for a value that does nothing
    other = run("--lens", str(2 * camera["lens"]))
    assert "is up to date" not in other
    single = tmp_path / "single.exr"
    run_ok(hbao_tool, fixture_path(name), "-o", single, "--camera", camera_path(name),
           "--lens", str(2 * camera["lens"]))
    assert (tmp_path / "ao_2.exr").read_bytes() == single.read_bytes()


def test_sequence_redoes_an_output_cut_short_or_damaged_since(hbao_tool, tmp_path):
    """An output whose header is whole but whose pixels are not (cut short by
    an interrupted copy, its end overwritten) is not up to date: it was
    skipped with exit 0, though it could not be read."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    expected = {frame: (folder / f"ao_{frame:04d}.exr").read_bytes() for frame in sources}
    cut = folder / "ao_0001.exr"
    cut.write_bytes(expected[1][:2000])
    damaged = folder / "ao_0002.exr"
    damaged.write_bytes(expected[2][:-200] + bytes(200))
    for path in (cut, damaged):
        preview = path.with_suffix(".png")
        os.utime(preview, (path.stat().st_mtime + 1,) * 2)  # the preview is not what is stale
    rerun = run_sequence(hbao_tool, folder)
    assert rerun.stderr.count("is up to date, skipped") == 1, rerun.stderr  # frame 4
    assert "frame 4: " in rerun.stderr and "ao_0004.exr is up to date" in rerun.stderr
    for frame in sources:
        assert (folder / f"ao_{frame:04d}.exr").read_bytes() == expected[frame]


@pytest.mark.parametrize("sealed", [True, False])
def test_sequence_redoes_a_frame_whose_preview_is_cut_short_or_damaged(
        hbao_tool, tmp_path, sealed):
    """A --preview PNG newer than its EXR is up to date only where it is whole:
    an emptied one and one with a byte changed inside its image data were
    skipped, left broken. Sealed, its seal tells (output_seal.h); unsealed (a
    copy that dropped extended attributes), its chunks' CRCs up to IEND at
    its end (png_check.h)."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    previews = {frame: (folder / f"ao_{frame:04d}.png").read_bytes() for frame in sources}
    exrs = {frame: (folder / f"ao_{frame:04d}.exr").read_bytes() for frame in sources}
    if not sealed:
        for frame in sources:
            os.removexattr(folder / f"ao_{frame:04d}.png", SEAL)
    (folder / "ao_0001.png").write_bytes(b"")  # in place: a seal stays
    damaged = bytearray(previews[2])
    image_data = damaged.index(b"IDAT") + 4
    damaged[image_data + 10] ^= 0x40
    (folder / "ao_0002.png").write_bytes(bytes(damaged))
    for frame in (1, 2):  # newer than their EXRs: only the content is wrong
        exr_time = (folder / f"ao_{frame:04d}.exr").stat().st_mtime
        os.utime(folder / f"ao_{frame:04d}.png", (exr_time + 1,) * 2)
    rerun = run_sequence(hbao_tool, folder)
    assert rerun.stderr.count("is up to date, skipped") == 1, rerun.stderr
    assert "ao_0004.exr is up to date" in rerun.stderr
    for frame in sources:
        assert (folder / f"ao_{frame:04d}.png").read_bytes() == previews[frame]
        assert (folder / f"ao_{frame:04d}.exr").read_bytes() == exrs[frame]
    again = run_sequence(hbao_tool, folder)
    assert again.stderr.count("is up to date, skipped") == 3, again.stderr


def test_sequence_redoes_a_frame_whose_preview_is_another_frames(hbao_tool, tmp_path):
    """Another frame's preview, whole, copied into a frame's place with its
    attributes (cp -a, rsync -aX) and newer than the frame's EXR: its PNG
    chunks are whole, and it was skipped. Its seal names the other frame's
    input: the frame is redone. A copy without the attributes has no seal
    to tell by, and is skipped (README)."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    previews = {frame: (folder / f"ao_{frame:04d}.png").read_bytes() for frame in sources}
    assert previews[1] != previews[2]
    swapped = folder / "ao_0001.png"
    shutil.copy2(folder / "ao_0002.png", swapped)  # with its extended attributes
    assert os.getxattr(swapped, SEAL) == os.getxattr(folder / "ao_0002.png", SEAL)
    exr_time = (folder / "ao_0001.exr").stat().st_mtime
    os.utime(swapped, (exr_time + 1,) * 2)  # not stale by its time
    rerun = run_sequence(hbao_tool, folder)
    assert rerun.stderr.count("is up to date, skipped") == 2, rerun.stderr
    assert "ao_0001.exr is up to date" not in rerun.stderr
    assert swapped.read_bytes() == previews[1]
    swapped.unlink()  # (a copy over it would keep its own seal, which tells)
    shutil.copyfile(folder / "ao_0002.png", swapped)  # no attributes: no seal
    os.utime(swapped, (exr_time + 1,) * 2)
    unsealed = run_sequence(hbao_tool, folder)
    assert unsealed.stderr.count("is up to date, skipped") == 3, unsealed.stderr
    assert swapped.read_bytes() == previews[2]


def test_sequence_redoes_a_preview_made_with_an_earlier_exr(hbao_tool, tmp_path):
    """A run with other settings and no --preview computes the EXRs again
    and leaves the previews as they were; touched (newer than the new EXRs)
    or restored with their times, those previews were skipped by the next
    run with --preview, though they show the earlier settings' AO. A
    preview's seal names the EXR it was made with: they are redone."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder, "--radius", "0.5")
    run_tool(hbao_tool, folder / "render_####.exr", "-o", folder / "ao_####.exr",
             "--frames", "1-5", "--no-normals", "--radius", "2")
    for frame in sources:
        exr_time = (folder / f"ao_{frame:04d}.exr").stat().st_mtime
        os.utime(folder / f"ao_{frame:04d}.png", (exr_time + 1,) * 2)
    rerun = run_sequence(hbao_tool, folder, "--radius", "2")
    assert "is up to date" not in rerun.stderr, rerun.stderr
    for frame in sources:
        single = tmp_path / f"single_{frame}.exr"
        run_ok(hbao_tool, fixture_path(sources[frame]), "-o", single, "--no-normals",
               "--radius", "2", "--preview", single.with_suffix(".png"))
        assert ((folder / f"ao_{frame:04d}.png").read_bytes()
                == single.with_suffix(".png").read_bytes())
    again = run_sequence(hbao_tool, folder, "--radius", "2")
    assert again.stderr.count("is up to date, skipped") == 3, again.stderr


def test_sequence_with_a_fifo_for_a_preview_does_not_wait_on_it(hbao_tool, tmp_path):
    """A FIFO in a preview's place, newer than its EXR, is not a PNG to
    check: the check must not open it for reading and wait for a writer
    that never comes (the run hung). The frame is redone, and its preview
    written into the FIFO for its reader, as a first run writes it."""
    folder, _ = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    expected = (folder / "ao_0002.png").read_bytes()
    preview = folder / "ao_0002.png"
    preview.unlink()
    os.mkfifo(preview)
    received = []
    reader = threading.Thread(target=lambda: received.append(preview.read_bytes()), daemon=True)
    reader.start()
    rerun = run_tool(hbao_tool, folder / "render_####.exr", "-o", folder / "ao_####.exr",
                     "--preview", folder / "ao_####.png", "--frames", "1-2", "--no-normals")
    reader.join(timeout=30)
    assert rerun.returncode == 0, rerun.stderr
    assert "ao_0001.exr is up to date" in rerun.stderr, rerun.stderr
    assert "ao_0002.exr is up to date" not in rerun.stderr, rerun.stderr
    assert received == [expected]


def test_sequence_redoes_an_output_whose_middle_chunks_are_overwritten(hbao_tool, tmp_path):
    """A stretch overwritten in an output's middle, longer than a chunk,
    breaks a chunk header (the open's structure check); the untouched frames
    are skipped."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    expected = {frame: (folder / f"ao_{frame:04d}.exr").read_bytes() for frame in sources}
    damaged = folder / "ao_0002.exr"
    size = len(expected[2])
    start, end = size * 2 // 5, size * 4 // 5
    with open(damaged, "r+b") as file:  # in place, as dd conv=notrunc: the seal stays
        file.seek(start)
        file.write(bytes(end - start))
    os.utime(damaged.with_suffix(".png"), (damaged.stat().st_mtime + 1,) * 2)
    rerun = run_sequence(hbao_tool, folder)
    assert rerun.stderr.count("is up to date, skipped") == 2, rerun.stderr
    assert "ao_0001.exr is up to date" in rerun.stderr
    assert "ao_0004.exr is up to date" in rerun.stderr
    for frame in sources:
        assert (folder / f"ao_{frame:04d}.exr").read_bytes() == expected[frame]


SEAL = "user.hbao.crc32"  # csrc/tool/output_seal.h


def test_outputs_are_sealed_with_their_crc(hbao_tool, tmp_path):
    """Each output carries the CRC-32 and size of its bytes, and its input's
    size, time and file name, in an extended attribute (both temporary-file
    paths), which a sequence rerun checks instead of decoding the output;
    its preview the same, with the EXR for its input."""
    for tmpfile in ("1", "0"):
        output = tmp_path / f"ao_{tmpfile}.exr"
        preview = output.with_suffix(".png")
        completed = run_tool(hbao_tool, fixture_path("eevee_half"), "-o", output, "--no-normals",
                             "--preview", preview, env=dict(os.environ, HBAO_TMPFILE=tmpfile))
        assert completed.returncode == 0, completed.stderr
        # the EXR names its input, the preview its EXR
        for sealed, source in ((output, fixture_path("eevee_half")), (preview, output)):
            data = sealed.read_bytes()
            seconds, nanoseconds = divmod(source.stat().st_mtime_ns, 10**9)
            assert os.getxattr(sealed, SEAL) == (
                f"crc32 {zlib.crc32(data):08x} size {len(data)} "
                f"input {source.stat().st_size} {seconds}.{nanoseconds:09d} "
                f"{source.name}").encode()


@pytest.mark.parametrize("sealed", [True, False])
def test_sequence_redoes_an_output_with_a_block_overwritten_inside_a_chunk(
        hbao_tool, tmp_path, sealed):
    """A 4 KiB block zeroed inside one chunk of an output (a bad sector, a
    hole punched, dd conv=notrunc) leaves every chunk header and the last
    chunk whole: only the bytes tell. Sealed, the CRC differs; unsealed (a
    copy that dropped extended attributes), the AO decodes whole and fails.
    Either way the frame is redone (a review found it skipped when only the
    structure and the last chunk were checked)."""
    folder = tmp_path / "sequence"
    folder.mkdir()
    camera = camera_path("cycles_float_zip").read_text()
    for frame in (1, 2):
        shutil.copyfile(fixture_path("cycles_float_zip"), folder / f"render_{frame}.exr")
    (folder / "cam.json").write_text(camera)
    arguments = (folder / "render_#.exr", "-o", folder / "ao_#.exr", "--camera",
                 folder / "cam.json", "--frames", "1-2")
    run_ok(hbao_tool, *arguments)
    damaged = folder / "ao_2.exr"
    expected = damaged.read_bytes()
    if not sealed:
        os.removexattr(damaged, SEAL)
    # inside the first of the three chunks' data: no header, not the last chunk
    start, size = first_chunk(damaged)
    assert size > 200
    with open(damaged, "r+b") as file:
        file.seek(start + size // 2)
        file.write(bytes(64))
    assert damaged.read_bytes() != expected
    rerun = run_tool(hbao_tool, *arguments)
    assert rerun.returncode == 0, rerun.stderr
    assert rerun.stderr.count("is up to date, skipped") == 1, rerun.stderr
    assert "ao_1.exr is up to date" in rerun.stderr
    assert damaged.read_bytes() == expected


def test_sequence_redoes_a_sealed_frame_whose_input_is_another_file(hbao_tool, tmp_path):
    """A sealed output names the input it was computed from (size and
    time): a rerun redoes a frame whose input was replaced by an older file
    (another render copied over it with its time kept, cp -p) and one into
    whose place another frame's output was copied with its attributes
    (cp -a). Both were skipped: each output was newer than its input, with
    the same settings and its own bytes."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    expected_4 = (folder / "ao_0004.exr").read_bytes()
    replaced = folder / "render_0001.exr"
    old_time = replaced.stat().st_mtime
    shutil.copyfile(fixture_path(sources[2]), replaced)
    os.utime(replaced, (old_time - 100,) * 2)  # older than its output
    for suffix in ("exr", "png"):
        shutil.copy2(folder / f"ao_0002.{suffix}", folder / f"ao_0004.{suffix}")
    assert os.getxattr(folder / "ao_0004.exr", SEAL) == os.getxattr(folder / "ao_0002.exr", SEAL)
    rerun = run_sequence(hbao_tool, folder)
    assert rerun.stderr.count("is up to date, skipped") == 1, rerun.stderr
    assert "ao_0002.exr is up to date" in rerun.stderr
    single = tmp_path / "single.exr"
    run_ok(hbao_tool, fixture_path(sources[2]), "-o", single, "--no-normals")
    assert (folder / "ao_0001.exr").read_bytes() == single.read_bytes()
    assert (folder / "ao_0004.exr").read_bytes() == expected_4
    again = run_sequence(hbao_tool, folder)
    assert again.stderr.count("is up to date, skipped") == 3, again.stderr


def test_sequence_tells_inputs_apart_by_name_and_forgives_a_rounded_time(hbao_tool, tmp_path):
    """Two frames rendered alike (one size, one time, even one content) are
    still two inputs: another frame's output copied into a frame's place
    with its attributes is redone. An input whose time a copy rounded down
    to a coarser file system's resolution (seconds, microseconds) is the
    same input; a time changed otherwise, by a nanosecond, is not."""
    folder = tmp_path / "sequence"
    folder.mkdir()
    same_time = 1_700_000_000_123_456_789
    for frame in (1, 2, 3, 4):
        render = folder / f"render_{frame:04d}.exr"
        shutil.copyfile(fixture_path("cycles_float_zip"), render)
        os.utime(render, ns=(same_time, same_time))
    arguments = (folder / "render_####.exr", "-o", folder / "ao_####.exr", "--frames", "1-4",
                 "--no-normals")
    run_ok(hbao_tool, *arguments)
    shutil.copy2(folder / "ao_0002.exr", folder / "ao_0001.exr")
    rounded = {2: same_time // 10**9 * 10**9, 3: same_time // 1000 * 1000, 4: same_time + 1}
    for frame, time in rounded.items():
        os.utime(folder / f"render_{frame:04d}.exr", ns=(time, time))
    rerun = run_ok(hbao_tool, *arguments)
    assert rerun.stderr.count("is up to date, skipped") == 2, rerun.stderr
    assert "ao_0002.exr is up to date" in rerun.stderr
    assert "ao_0003.exr is up to date" in rerun.stderr
    again = run_ok(hbao_tool, *arguments)
    assert again.stderr.count("is up to date, skipped") == 4, again.stderr


def test_sequence_reads_an_earlier_versions_seal_as_none(hbao_tool, tmp_path):
    """Session 40's seal ("crc32 ... size ...", no input) is no seal to this
    version: the output's AO is decoded instead, so a whole one is skipped
    (a farm's outputs are not all recomputed after an upgrade) and one with
    a chunk damaged is redone."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder)
    expected = {frame: (folder / f"ao_{frame:04d}.exr").read_bytes() for frame in sources}
    for frame in sources:
        output = folder / f"ao_{frame:04d}.exr"
        data = output.read_bytes()
        os.setxattr(output, SEAL, f"crc32 {zlib.crc32(data):08x} size {len(data)}".encode())
    damaged = folder / "ao_0002.exr"
    start, size = first_chunk(damaged)
    with open(damaged, "r+b") as file:
        file.seek(start + size // 2)
        file.write(bytes(64))
    os.utime(folder / "ao_0002.png", (damaged.stat().st_mtime + 1,) * 2)
    rerun = run_sequence(hbao_tool, folder)
    assert rerun.stderr.count("is up to date, skipped") == 2, rerun.stderr
    assert "frame 2: " in rerun.stderr and "ao_0002.exr is up to date" not in rerun.stderr
    for frame in sources:
        assert (folder / f"ao_{frame:04d}.exr").read_bytes() == expected[frame]


def test_sequence_redoes_frames_whose_camera_clip_end_changed(hbao_tool, tmp_path):
    """The camera file's clip_end decides which depths are background: a
    rerun with one that differs only there recomputes (it was taken as up
    to date: the stamp left clip_end out)."""
    folder = tmp_path / "sequence"
    folder.mkdir()
    shutil.copyfile(fixture_path("cycles_float_zip"), folder / "render_0001.exr")
    camera = json.loads(camera_path("cycles_float_zip").read_text())
    cameras = {}
    for name, clip_end in (("far", 100.0), ("near", 5.5)):
        cameras[name] = tmp_path / f"{name}.json"
        cameras[name].write_text(json.dumps(dict(camera, clip_end=clip_end)))
    os.utime(folder / "render_0001.exr", (1e9, 1e9))
    for path in cameras.values():
        os.utime(path, (1e9, 1e9))  # both older than any output
    outputs = {}
    for name in ("far", "near"):
        completed = run_ok(hbao_tool, folder / "render_####.exr", "-o", folder / "ao_####.exr",
                           "--camera", cameras[name], "--frames", "1")
        assert "up to date" not in completed.stderr, (name, completed.stderr)
        outputs[name] = (folder / "ao_0001.exr").read_bytes()
        single = tmp_path / f"single_{name}.exr"
        run_ok(hbao_tool, folder / "render_0001.exr", "-o", single, "--camera", cameras[name])
        assert outputs[name] == single.read_bytes(), name
    assert outputs["far"] != outputs["near"]


def test_an_input_replaced_while_its_ao_is_computed_gets_no_output(hbao_tool, tmp_path):
    """A farm re-renders a frame while hbao computes its AO: an output written
    then would be the old render's AO, newer than the new render, and a
    sequence's rerun would skip it. hbao writes nothing and says to run
    again. (The camera file, a FIFO, holds the run after the render is
    opened; the render is replaced meanwhile, as a renderer's save does.)"""
    render = tmp_path / "render.exr"
    shutil.copyfile(fixture_path("cycles_float_zip"), render)
    camera = tmp_path / "camera.json"
    os.mkfifo(camera)
    output = tmp_path / "ao.exr"
    process = subprocess.Popen([str(hbao_tool), str(render), "-o", str(output), "--camera",
                                str(camera)], stderr=subprocess.PIPE, text=True)
    with open(camera, "w") as writer:  # hbao has opened the render by now
        shutil.copyfile(fixture_path("eevee_half"), tmp_path / "new.exr")
        older = render.stat().st_mtime_ns - 10**9
        os.utime(tmp_path / "new.exr", ns=(older, older))
        os.replace(tmp_path / "new.exr", render)
        writer.write(camera_path("cycles_float_zip").read_text())
    _, stderr = process.communicate(timeout=TOOL_TIMEOUT_S)
    completed = subprocess.CompletedProcess(process.args, process.returncode, "", stderr)
    assert_clean_error(completed, EXIT_RUNTIME, "changed while its AO was computed")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["camera.json", "render.exr"]


def test_sequence_of_every_second_frame(hbao_tool, tmp_path):
    """A render with Blender's Frame Step 2 writes frames 1, 3, 5: the
    sequence "1-6x2" computes those (1-6 failed on each missing frame, and
    listing them took a range each, at most 64; found by an exploratory
    run). No frame may be in two ranges: "1-9x2,2-10x2" share none,
    "1-9x2,5" and "1-10x3,4-7x3" do."""
    for frame in (1, 3, 5):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}.exr")
    run_ok(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "ao_#.exr", "--frames", "1-6x2",
           "--no-normals")
    assert sorted(p.name for p in tmp_path.glob("ao_*")) == ["ao_1.exr", "ao_3.exr", "ao_5.exr"]
    for frames, accepted in (("1-9x2,2-10x2", True), ("0-1048574x1048574", True),
                             ("1-9x2,5", False), ("1-10x3,4-7x3", False), ("1-9x0", False),
                             ("5x2", False), ("1-9x", False), ("1-9x-2", False)):
        completed = run_tool(hbao_tool, tmp_path / "none_#.exr", "-o", tmp_path / "x_#.exr",
                             "--frames", frames, "--no-normals")
        # accepted: the frames are tried (and fail: no input); refused: a usage error
        assert completed.returncode == (EXIT_RUNTIME if accepted else EXIT_USAGE), \
            (frames, completed.stderr)


def test_sequence_output_that_is_its_own_input_is_refused_even_if_up_to_date(hbao_tool,
                                                                             tmp_path):
    """An input that is an earlier --keep-input output of the same settings
    looks up to date as its own output: it is refused (exit 2), as with
    --force, not skipped with exit 0."""
    kept = tmp_path / "k_0001.exr"
    run_ok(hbao_tool, fixture_path("cycles_float_zip"), "-o", kept, "--keep-input",
           "--no-normals")
    for extra in ([], ["--force"]):
        completed = run_tool(hbao_tool, tmp_path / "k_####.exr", "-o", tmp_path / "k_####.exr",
                             "--keep-input", "--no-normals", "--frames", "1", *extra)
        assert_clean_error(completed, EXIT_USAGE, "is the input file")


def test_sequence_reads_the_camera_file_once(hbao_tool, tmp_path):
    """--camera /dev/stdin (or a shell's <(...)): a pipe reads once. Every
    frame gets its camera, as from a file; a camera file that cannot be read
    fails the run before any frame."""
    for frame in (1, 2, 3):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}.exr")
    arguments = [str(hbao_tool), str(tmp_path / "in_#.exr"), "-o", str(tmp_path / "p_#.exr"),
                 "--frames", "1-3", "--camera", "/dev/stdin"]
    piped = subprocess.run(arguments, input=camera_path("cycles_float_zip").read_text(),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           timeout=TOOL_TIMEOUT_S)
    assert piped.returncode == 0, piped.stderr
    # A pipe's time is when it was written: a rerun goes by what it holds.
    again = subprocess.run(arguments, input=camera_path("cycles_float_zip").read_text(),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           timeout=TOOL_TIMEOUT_S)
    assert again.returncode == 0 and again.stderr.count("up to date, skipped") == 3, again.stderr
    from_file = tmp_path / "single.exr"
    compute_ao(hbao_tool, "cycles_float_zip", from_file)
    for frame in (1, 2, 3):
        assert (tmp_path / f"p_{frame}.exr").read_bytes() == from_file.read_bytes()
    missing = run_tool(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "m_#.exr", "--frames",
                       "1-3", "--camera", tmp_path / "none.json")
    assert_clean_error(missing, EXIT_RUNTIME, "none.json")
    assert "frame" not in missing.stderr and not list(tmp_path.glob("m_*"))


def test_sequence_redoes_frames_computed_with_another_camera(hbao_tool, tmp_path):
    """The camera file counts by what it holds, not by its time: adding a
    forgotten --camera, or naming another (older) file, recomputes."""
    name = "cycles_float_zip"
    folder = tmp_path / "sequence"
    folder.mkdir()
    shutil.copyfile(fixture_path(name), folder / "render_0001.exr")
    first = tmp_path / "first.json"
    shutil.copyfile(camera_path(name), first)
    camera = json.loads(first.read_text())
    camera["lens"] *= 2
    second = tmp_path / "second.json"
    second.write_text(json.dumps(camera))
    long_ago = 10**9 * 10**9  # 2001: older than every output
    os.utime(second, ns=(long_ago, long_ago))

    def run(*extra):
        return run_ok(hbao_tool, folder / "render_####.exr", "-o", folder / "ao_####.exr",
                      "--frames", "1", *extra)

    run()  # without a camera (a warning)
    for camera_file in (first, second):
        assert "up to date" not in run("--camera", camera_file).stderr
        assert "is up to date, skipped" in run("--camera", camera_file).stderr
        single = tmp_path / "single.exr"
        run_ok(hbao_tool, fixture_path(name), "-o", single, "--camera", camera_file)
        assert (folder / "ao_0001.exr").read_bytes() == single.read_bytes()
    assert "up to date" not in run().stderr


def turned_camera(name, degrees):
    """The fixture's camera turned about its own vertical axis."""
    camera = json.loads(camera_path(name).read_text())
    angle = np.radians(degrees)
    turn = np.array([[np.cos(angle), 0, np.sin(angle), 0], [0, 1, 0, 0],
                     [-np.sin(angle), 0, np.cos(angle), 0], [0, 0, 0, 1]])
    camera["world_to_camera"] = (turn @ np.array(camera["world_to_camera"])).tolist()
    return camera


def test_sequence_takes_each_frames_camera_from_a_pattern(hbao_tool, tmp_path):
    """An animated camera: --camera 'cam_#.json' gives each frame its own
    camera file (the normals' rotation differs per frame), and a frame whose
    camera file is missing fails alone. A rerun skips the frames whose camera
    held the same, and recomputes one whose camera changed."""
    name = "cycles_float_zip"
    for frame in (1, 2, 3):
        shutil.copyfile(fixture_path(name), tmp_path / f"in_{frame}.exr")
    shutil.copyfile(camera_path(name), tmp_path / "cam_1.json")
    (tmp_path / "cam_2.json").write_text(json.dumps(turned_camera(name, 20)))

    def run(*extra):
        return run_tool(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "ao_#.exr",
                        "--frames", "1-3", "--camera", tmp_path / "cam_#.json", *extra)

    completed = run()
    assert_clean_error(completed, EXIT_RUNTIME, "1 of 3 frames failed: 3", "cam_3.json")
    for frame in (1, 2):
        single = tmp_path / f"single_{frame}.exr"
        run_ok(hbao_tool, fixture_path(name), "-o", single, "--camera",
               tmp_path / f"cam_{frame}.json")
        assert (tmp_path / f"ao_{frame}.exr").read_bytes() == single.read_bytes()
    assert (tmp_path / "ao_1.exr").read_bytes() != (tmp_path / "ao_2.exr").read_bytes()
    assert not (tmp_path / "ao_3.exr").exists()

    (tmp_path / "cam_2.json").write_text(json.dumps(turned_camera(name, 40)))
    long_ago = 10**9 * 10**9  # older than every output: only its contents changed
    os.utime(tmp_path / "cam_2.json", ns=(long_ago, long_ago))
    shutil.copyfile(camera_path(name), tmp_path / "cam_3.json")
    again = run()
    assert again.returncode == 0, again.stderr
    assert "frame 1: " in again.stderr and again.stderr.count("is up to date, skipped") == 1
    single = tmp_path / "single_2b.exr"
    run_ok(hbao_tool, fixture_path(name), "-o", single, "--camera", tmp_path / "cam_2.json")
    assert (tmp_path / "ao_2.exr").read_bytes() == single.read_bytes()
    assert (tmp_path / "ao_3.exr").read_bytes() == (tmp_path / "ao_1.exr").read_bytes()


def test_a_camera_in_a_folder_with_a_hash_is_one_camera(hbao_tool, tmp_path):
    """A camera in a folder like 'shot#1' that exists is read once, as before
    per-frame cameras (a review found every frame failing on
    'shot11/cam.json'). Where no file has the path as written, a '#' run in
    a folder is the frame, as in the input's and -o's folders: 'shot_#/cam.json'
    was read literally and every frame failed (an exploratory run); not
    where the path cannot be looked up (a review: 'Permission denied' became
    a missing file of each frame)."""
    folder = tmp_path / "shot#1"
    folder.mkdir()
    shutil.copyfile(camera_path("cycles_float_zip"), folder / "cam.json")
    for frame in (1, 2):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}.exr")
    run_ok(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "ao_#.exr", "--frames", "1-2",
           "--camera", folder / "cam.json")
    single = tmp_path / "single.exr"
    compute_ao(hbao_tool, "cycles_float_zip", single)
    assert (tmp_path / "ao_2.exr").read_bytes() == single.read_bytes()
    name = "cycles_float_zip"
    for frame, turn in ((1, 0), (2, 30)):
        shot = tmp_path / f"shot_{frame}"
        shot.mkdir()
        shutil.copyfile(fixture_path(name), shot / "render.exr")
        (shot / "cam.json").write_text(json.dumps(turned_camera(name, turn)))
    run_ok(hbao_tool, tmp_path / "shot_#" / "render.exr", "-o", tmp_path / "shot_#" / "ao.exr",
           "--frames", "1-2", "--camera", tmp_path / "shot_#" / "cam.json")
    for frame in (1, 2):
        single = tmp_path / f"single_{frame}.exr"
        run_ok(hbao_tool, fixture_path(name), "-o", single, "--camera",
               tmp_path / f"shot_{frame}" / "cam.json")
        assert (tmp_path / f"shot_{frame}" / "ao.exr").read_bytes() == single.read_bytes()
    assert (tmp_path / "shot_1" / "ao.exr").read_bytes() != \
        (tmp_path / "shot_2" / "ao.exr").read_bytes()
    # a camera path that exists but cannot be looked up (here a folder that
    # is a link to itself; for others an unreadable folder) is one camera,
    # with the reason, not a frame pattern whose frames lack their files
    (tmp_path / "take #1").symlink_to(tmp_path / "take #1")
    refused = run_tool(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "loop_#.exr",
                       "--frames", "1-2", "--camera", tmp_path / "take #1" / "cam.json")
    assert_clean_error(refused, EXIT_RUNTIME, "take #1/cam.json: Too many levels of symbolic")


def test_sequence_refuses_an_output_that_is_another_frames_camera(hbao_tool, tmp_path):
    """-o 'x_#.exr' with --camera 'x_#0.exr' --frames 1-10: frame 10's output
    would replace frame 1's camera file before frame 1 reads it."""
    for frame in range(1, 11):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}.exr")
    completed = run_tool(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "x_#.exr",
                         "--frames", "1-10", "--camera", tmp_path / "x_#0.exr")
    assert_clean_error(completed, EXIT_USAGE, "is the --camera file of frame 1")
    assert not list(tmp_path.glob("x_*"))


def test_sequence_refuses_an_output_that_is_the_one_camera_file(hbao_tool, tmp_path):
    """-o 'cam_#.json' --camera cam_3.json --frames 1-5 (one camera for every
    frame): frame 3's output would replace the camera file after frames 1
    and 2 read it. It was refused only when frame 3 came, with frames 1, 2,
    4 and 5 written (an exploratory run); now before any frame runs, by
    name and through a symbolic link."""
    camera = camera_path("cycles_float_zip").read_text()
    for frame in range(1, 6):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"render_{frame}.exr")
    (tmp_path / "cam_3.json").write_text(camera)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    completed = run_tool(hbao_tool, tmp_path / "render_#.exr", "-o", tmp_path / "cam_#.json",
                         "--camera", tmp_path / "cam_3.json", "--frames", "1-5")
    assert_clean_error(completed, EXIT_USAGE, "-o of frame 3",
                       "is the --camera file that every frame reads")
    (tmp_path / "ao_2.exr").symlink_to("cam_3.json")
    linked = run_tool(hbao_tool, tmp_path / "render_#.exr", "-o", tmp_path / "ao_#.exr",
                      "--camera", tmp_path / "cam_3.json", "--frames", "1-5")
    assert_clean_error(linked, EXIT_USAGE, "-o of frame 2",
                       "is the --camera file that every frame reads")
    os.unlink(tmp_path / "ao_2.exr")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_sequence_refuses_an_output_that_links_to_another_frames_output(hbao_tool, tmp_path):
    """a_2.exr a symbolic link to a_1.exr (held frames linked to save space,
    then the shot rendered again): frame 2 wrote frame 1's output through
    the link, frame 1 then found it up to date and skipped it, and the run
    exited 0 with frame 2's AO as frame 1's (an exploratory run; with
    --force two jobs raced into one file). Refused before any frame runs,
    whether the target exists or not yet, and the same for a preview."""
    shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / "r_1.exr")
    shutil.copyfile(fixture_path("ortho_float"), tmp_path / "r_2.exr")

    def run(*extra):
        return run_tool(hbao_tool, tmp_path / "r_#.exr", "-o", tmp_path / "a_#.exr",
                        "--frames", "2,1", "--no-normals", *extra)

    (tmp_path / "a_2.exr").symlink_to("a_1.exr")  # not there yet: by the name it writes
    assert_clean_error(run(), EXIT_USAGE, "-o of frame 2", "is the -o of frame 1")
    assert not (tmp_path / "a_1.exr").exists()
    run_ok(hbao_tool, tmp_path / "r_1.exr", "-o", tmp_path / "a_1.exr", "--no-normals")
    first = (tmp_path / "a_1.exr").read_bytes()
    for extra in ((), ("--force", "--jobs", "2")):  # there
        assert_clean_error(run(*extra), EXIT_USAGE, "-o of frame 2", "is the -o of frame 1")
        assert (tmp_path / "a_1.exr").read_bytes() == first
    (tmp_path / "p_1.png").symlink_to("a_2.exr")  # a preview through a link to an output
    os.unlink(tmp_path / "a_2.exr")
    previews = run("--preview", tmp_path / "p_#.png")  # (frame 2 comes first)
    assert_clean_error(previews, EXIT_USAGE, "-o of frame 2", "is the --preview of frame 1")
    assert (tmp_path / "a_1.exr").read_bytes() == first and not (tmp_path / "a_2.exr").exists()
    # each frame its own output: runs, and a rerun skips both
    os.unlink(tmp_path / "p_1.png")
    run_ok(hbao_tool, tmp_path / "r_#.exr", "-o", tmp_path / "a_#.exr", "--frames", "2,1",
           "--no-normals")
    assert (tmp_path / "a_2.exr").is_file() and not (tmp_path / "a_2.exr").is_symlink()


def test_sequence_refuses_two_frames_that_write_one_new_file_by_other_paths(hbao_tool, tmp_path):
    """-o 'd#/ao.exr' with d1 and d2 links to one folder, or -o
    'e#/../ao.exr': frames 1 and 2 wrote one file that was not there yet,
    the run exited 0 with frame 1's AO lost, and the same command then
    refused the run (a review's runs; the check by file saw only files that
    exist). Refused before any frame runs, the folder entry named; a
    preview the same; each frame a file of its own runs."""
    shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / "r_1.exr")
    shutil.copyfile(fixture_path("ortho_float"), tmp_path / "r_2.exr")
    (tmp_path / "shared").mkdir()
    for frame in (1, 2):
        (tmp_path / f"d{frame}").symlink_to("shared")
        (tmp_path / f"e{frame}").mkdir()
    before = sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*"))

    def run(output, *extra):
        return run_tool(hbao_tool, tmp_path / "r_#.exr", "-o", tmp_path / output,
                        "--frames", "1-2", "--no-normals", *extra)

    for output, entry in (("d#/ao.exr", "shared/ao.exr"), ("e#/../ao.exr", "ao.exr")):
        assert_clean_error(run(output), EXIT_USAGE, "-o of frame 2", "is the -o of frame 1",
                           f"both {tmp_path / entry}")
    assert_clean_error(run("e#/ao.exr", "--preview", tmp_path / "e#/../p.png"), EXIT_USAGE,
                       "--preview of frame 2", "is the --preview of frame 1")
    assert sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*")) == before
    run_ok(hbao_tool, tmp_path / "r_#.exr", "-o", tmp_path / "e#/ao.exr", "--frames", "1-2",
           "--no-normals")
    assert (tmp_path / "e1" / "ao.exr").is_file() and (tmp_path / "e2" / "ao.exr").is_file()


def test_sequence_progress_lines_escape_the_path(hbao_tool, tmp_path):
    """A frame's progress line printed its output's name raw, where every
    message escapes it: an escape sequence in the name drove the terminal,
    a newline split the frame's one line in two."""
    shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / "r_1.exr")
    completed = run_ok(hbao_tool, tmp_path / "r_#.exr", "-o", tmp_path / "a\x1b[31m\nb_#.exr",
                       "--frames", "1", "--no-normals")
    lines = [line for line in completed.stderr.splitlines() if "[1/1] frame 1" in line]
    assert len(lines) == 1 and "a\\x1b[31m\\x0ab_1.exr" in lines[0], completed.stderr
    assert "\x1b" not in completed.stderr and (tmp_path / "a\x1b[31m\nb_1.exr").is_file()


EXPORT_CAMERAS = SCRIPTS / "export_cameras.py"
SCRIPTS_IN_BLENDER = Path(__file__).resolve().parent / "blender_scripts"


@pytest.mark.matrix
def test_export_cameras_writes_each_frames_camera(hbao_tool, run_in_blender, blender,
                                                  tmp_path):
    """scripts/export_cameras.py on a .blend whose camera turns and zooms
    (and a marker switches cameras): each frame's file holds the camera
    Blender evaluates at that frame, which the CLI's sequence reads per frame;
    a rerun leaves files that would not change as they are."""
    blend, expected_path = tmp_path / "anim.blend", tmp_path / "expected.json"
    run_in_blender(SCRIPTS_IN_BLENDER / "animated_camera.py", blend, expected_path,
                   addon=False)
    expected = json.loads(expected_path.read_text())
    pattern = tmp_path / "cams" / "cam_##.json"
    run_in_blender(EXPORT_CAMERAS, pattern, blend=blend)
    cameras = {}
    for frame in range(1, 5):
        cameras[frame] = json.loads((tmp_path / "cams" / f"cam_{frame:02d}.json").read_text())
        assert np.allclose(cameras[frame]["world_to_camera"],
                           expected[str(frame)]["world_to_camera"], atol=1e-5), frame
        assert cameras[frame]["lens"] == pytest.approx(expected[str(frame)]["lens"])
    assert not np.allclose(cameras[1]["world_to_camera"], cameras[3]["world_to_camera"])
    assert cameras[3]["lens"] == pytest.approx(1.5 * cameras[1]["lens"])
    assert not np.allclose(cameras[3]["world_to_camera"], cameras[4]["world_to_camera"])
    # readable by the farm's other users, as a file the shell makes (umask 022)
    assert all(p.stat().st_mode & 0o777 == 0o644 for p in (tmp_path / "cams").iterdir())
    times = {p: p.stat().st_mtime_ns for p in (tmp_path / "cams").iterdir()}
    again = run_in_blender(EXPORT_CAMERAS, pattern, "--frames", "2-3,1", blend=blend)
    assert "0 files written, 3 already up to date" in again.stdout
    assert {p: p.stat().st_mtime_ns for p in (tmp_path / "cams").iterdir()} == times
    for frame in range(1, 5):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}.exr")
    run_ok(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "ao_#.exr", "--frames", "1-4",
           "--camera", tmp_path / "cams" / "cam_##.json")
    # every third frame from 1: frames 1 (up to date) and 4 (written again), not 2 or 3
    for frame in (2, 3, 4):
        (tmp_path / "cams" / f"cam_{frame:02d}.json").unlink()
    stepped = run_in_blender(EXPORT_CAMERAS, pattern, "--frames", "1-4x3", blend=blend)
    assert "2 frames, 1 files written, 1 already up to date" in stepped.stdout
    assert sorted(p.name for p in (tmp_path / "cams").iterdir()) == ["cam_01.json", "cam_04.json"]
    # In a folder with a default ACL (a farm's shared folder granting a group
    # write access), a new file has the ACL's permissions, as any program's
    # new file there; a file it rewrites keeps its own (the script set the
    # umask's mode on both, taking the group's write access away: a review)
    shared = tmp_path / "shared"
    shared.mkdir()
    subprocess.run(["setfacl", "-m", "g:users:rwx", "-d", "-m", "g:users:rwx", str(shared)],
                   check=True)
    (shared / "reference").write_bytes(b"")
    (shared / "cam_01.json").write_text("{}")  # another camera's: rewritten
    (shared / "cam_01.json").chmod(0o600)
    run_in_blender(EXPORT_CAMERAS, shared / "cam_##.json", "--frames", "1-2", blend=blend)
    assert json.loads((shared / "cam_01.json").read_text()) == cameras[1]
    assert stat.S_IMODE((shared / "cam_01.json").stat().st_mode) == 0o600
    assert acl_text(shared / "cam_02.json") == acl_text(shared / "reference")
    assert "group:users:rwx" in acl_text(shared / "cam_02.json")
    assert sorted(p.name for p in shared.iterdir()) == ["cam_01.json", "cam_02.json",
                                                        "reference"]


@pytest.mark.matrix
def test_export_cameras_takes_the_shutter_middle_with_motion_blur(
        run_in_blender, blender, tmp_path):
    """With Cycles' camera motion blur the passes show the camera at the
    middle of the shutter, as the node takes it: half a frame on with
    Position Start and a shutter of a frame. export_cameras.py wrote the
    camera at the frame: the CLI's AO then was 0.02-0.23 off the node's
    (found by an exploratory run). The camera object stays the frame's (a
    marker switches it at frame 4)."""
    blend, expected_path = tmp_path / "anim.blend", tmp_path / "expected.json"
    run_in_blender(SCRIPTS_IN_BLENDER / "animated_camera.py", blend, expected_path,
                   "--motion-blur-start", addon=False)
    expected = json.loads(expected_path.read_text())
    pattern = tmp_path / "cams" / "cam_##.json"
    run_in_blender(EXPORT_CAMERAS, pattern, blend=blend)
    for frame in range(1, 5):
        written = json.loads((tmp_path / "cams" / f"cam_{frame:02d}.json").read_text())
        assert np.allclose(written["world_to_camera"], expected[str(frame)]["world_to_camera"],
                           atol=1e-5), frame
        assert written["lens"] == pytest.approx(expected[str(frame)]["lens"]), frame
    # the camera turns between frames 1 and 3: at the frame it differs
    assert not np.allclose(expected["1"]["world_to_camera"], expected["1"]["at_frame"],
                           atol=1e-3)


@pytest.mark.matrix
@pytest.mark.parametrize("stereo", [
    {"stereo": True},
    {"stereo": True, "stereo_settings": {"convergence_mode": "TOE", "pivot": "CENTER",
                                         "interocular_distance": 0.3}},
    {"stereo": True, "stereo_settings": {"convergence_mode": "TOE", "pivot": "RIGHT",
                                         "interocular_distance": 0.3}},
    {"stereo": True, "stereo_settings": {"convergence_mode": "PARALLEL", "pivot": "CENTER",
                                         "interocular_distance": 0.3}},
    {"stereo": True, "stereo_settings": {"pivot": "RIGHT", "interocular_distance": 0.3}},
    {"stereo": "custom_view"}, {"stereo": "one_view"}],
    ids=["offaxis_left", "toe_center", "toe_right", "parallel_center", "offaxis_right",
         "multi_view", "one_view"])
def test_export_cameras_writes_each_views_camera(run_in_blender, blender, hbao_tool, tmp_path,
                                                 stereo):
    """With Stereoscopy, export_cameras.py writes a camera per view
    (cam_0001_L.json beside render_0001_L.exr): a Stereo 3D eye as Blender
    places it (stereo_eyes.py, in each convergence mode and pivot), a
    Multi-View view's own camera. It wrote the scene camera alone: the CLI's
    AO of the right eye was 0.40 off the node's (found by an exploratory
    run). The CLI on each view's passes with that view's file gives the
    node's AO, which Blender's own placement of the eye gave (the engine's
    camera_model_matrix). With one view on, the camera's file is named as
    Blender names that render (3.4 without the view's suffix)."""
    from test_addon import exr, node_outputs, render
    blend = tmp_path / "stereo.blend"
    node = {"radius": 0.7, "blur_size": 0}
    out, _ = render(run_in_blender, tmp_path, dict(stereo, nodes=[node],
                                                   save_blend_after=str(blend)))
    pattern = tmp_path / "cams" / "cam_####.json"
    run_in_blender(EXPORT_CAMERAS, pattern, "--frames", "1", blend=blend)
    suffixes = ["_L", "_R"] + (["_C"] if stereo["stereo"] == "custom_view" else [])
    if stereo["stereo"] == "one_view":  # (3.4 writes frame_0001.exr)
        suffixes = ["_L" if (out / "frame_0001_L.exr").exists() else ""]
        assert sorted(p.name for p in (tmp_path / "cams").iterdir()) == \
            [f"cam_0001{suffixes[0]}.json"]
    cameras = {}
    for suffix in suffixes:
        cameras[suffix] = json.loads((tmp_path / "cams" / f"cam_0001{suffix}.json").read_text())
        run_ok(hbao_tool, out / f"frame_0001{suffix}.exr", "-o", tmp_path / f"ao{suffix}.exr",
               "--camera", tmp_path / "cams" / f"cam_0001{suffix}.json", "--radius", "0.7",
               "--blur", "0")
        cli = exr.read_channels(tmp_path / f"ao{suffix}.exr", ["AO"])["AO"]
        node_view = suffix or ("_L" if (out / "nodes_0001_L.exr").exists() else "")
        node_ao = node_outputs(out, 1, view=node_view)["ao"]
        assert node_ao.min() < 0.9, suffix
        # (the eyes' matrices in float64 here, in float32 in Blender)
        assert np.abs(cli - node_ao).max() <= 2e-4, suffix
    if stereo["stereo"] != "one_view":
        assert not np.allclose(cameras["_L"]["world_to_camera"],
                               cameras["_R"]["world_to_camera"])
        assert not list((tmp_path / "cams").glob("cam_0001.json"))  # no mono camera beside


FRAME_LISTS = [
    "1", "0", "1-250", "1-10,20,30-40", "1-250x2", "1-9x2,2-10x2", "0-1048574x1048574",
    "1048574", "1048575", "0-1048575", "3-1", "1-3,2", "1-9x2,5", "1-10x3,4-7x3", "1-9x0",
    "5x2", "1-9x", "1-9x-2", "x2", "-1", "1-", "1,,2", "", " 1", "1 ", "+1", "1-3, 5",
    "\u0661", "\u0661-\u0663", "\uff10", "0000000000000001", "00000000000000001-2",
    "000000000000001", "1-2x000000000000002", "1-4x3", "10-1x1",
    ",".join(str(2 * k) for k in range(64)), ",".join(str(2 * k) for k in range(65)),
    ",".join(f"{k}-1048574x64" for k in range(63)) + ",5"]


def test_export_cameras_frames_are_the_clis(hbao_tool, tmp_path):
    """The script takes --frames as the CLI does (scripts/frame_lists.py;
    the CLI's parser is csrc/tool/frame_pattern.c): its limits are the
    CLI's, and each list of a table is taken by both or by neither, with
    the same frames (the script took Unicode digits and 16-digit numbers
    that the CLI refuses: found by a review)."""
    import frame_lists
    header = (REPO / "csrc" / "tool" / "frame_pattern.h").read_text()
    for name in ("FRAME_MAX", "FRAME_RANGES_MAX"):
        in_header = int(re.search(rf"#define {name} (\d+)", header).group(1))
        assert getattr(frame_lists, name) == in_header, name
    for text in FRAME_LISTS:
        try:
            frames = frame_lists.parse(text)
        except ValueError:
            frames = None
        # a file that is no EXR for the first frame (so that not every
        # listed frame lacks its input, which is one error without a list)
        for stale in tmp_path.glob("none_*.exr"):
            stale.unlink()
        if frames:
            (tmp_path / f"none_{frames[0]}.exr").write_bytes(b"")
        completed = run_tool(hbao_tool, tmp_path / "none_#.exr", "-o", tmp_path / "x_#.exr",
                             "--frames", text, "--no-normals", "-j", "32")
        # taken: every frame failing (no EXR, no input); refused: a usage error
        assert completed.returncode == (EXIT_USAGE if frames is None else EXIT_RUNTIME), \
            (text[:40], completed.stderr[-300:])
        if frames is not None and len(frames) < 50:
            failed = re.search(r"failed: ([0-9, -]+)", completed.stderr)
            listed = []
            for item in failed.group(1).split(", ") if failed else []:
                first, _, last = item.partition("-")
                listed += range(int(first), int(last or first) + 1)
            assert listed == frames, (text, completed.stderr[-300:])


@pytest.mark.parametrize("arguments, status, fragment", [
    (["cam.json"], EXIT_USAGE, "needs a run of '#'"),
    (["shot#/cam.json"], EXIT_USAGE, "in its file name"),
    (["render_####.exr"], EXIT_USAGE, "camera files end in .json"),
    (["cam_#.json", "--frames", "3-1"], EXIT_USAGE, "first to last"),
    (["cam_#.json", "--frames", "1-3,2"], EXIT_USAGE, "overlap"),
    (["cam_#.json", "--frames", "1-9x2,5"], EXIT_USAGE, "overlap"),
    (["cam_#.json", "--frames", "1-9x0"], EXIT_USAGE, "by a step of 1 or more"),
    (["cam_#.json", "--frames", "1-3, 5"], EXIT_USAGE, "not a frame list"),
    (["cam_#.json", "--frames", ",".join(str(2 * k) for k in range(65))], EXIT_USAGE,
     "more than 64 ranges"),
])
def test_export_cameras_refuses_bad_arguments(run_blender, tmp_path, arguments, status,
                                              fragment):
    completed = run_blender(EXPORT_CAMERAS, tmp_path / arguments[0], *arguments[1:],
                            check=False)
    assert completed.returncode == status, completed.stdout
    assert fragment in completed.stdout
    assert not any(tmp_path.rglob("*")), "nothing is written"


def test_export_cameras_does_not_replace_a_file_its_user_may_not_write(run_blender):
    """A camera file the user may not write (approved and made read-only) is
    refused, as the CLI refuses such an output: the script's rename replaced
    it, its folder being writable. One that already holds the camera is left
    as it is, read-only or not. A symbolic link is written through, as the
    CLI writes its outputs (the script replaced the link with a file).
    Blender runs as another user (nobody) where the tests run as root, whom
    no permission stops."""
    folder = Path(tempfile.mkdtemp(prefix="hbao-readonly-"))  # nobody reaches it, not tmp_path
    try:
        folder.chmod(0o777)
        blend = folder / "anim.blend"
        run_blender(SCRIPTS_IN_BLENDER / "animated_camera.py", blend, folder / "expected.json",
                    addon=False)
        blend.chmod(0o644)
        approved = folder / "cam_2.json"
        approved.write_text("{}\n")
        approved.chmod(0o444)
        private = folder / "cam_3.json"  # another user's, which it may not even read
        private.write_text("{}\n")
        private.chmod(0o600)
        as_user = {"user": 65534, "group": 65534, "extra_groups": []} \
            if os.geteuid() == 0 else {}
        home = folder / "home"
        for made in (home, home / "config"):  # (a config folder missing: the real user's)
            made.mkdir(mode=0o777)
            made.chmod(0o777)
        env = dict(os.environ, HOME=str(home), BLENDER_USER_SCRIPTS=str(home / "scripts"),
                   BLENDER_USER_CONFIG=str(home / "config"), PYTHONUNBUFFERED="1")
        env.pop("PYTHONPATH", None)

        def export(frames):
            command = DEBIAN_BLENDER.command(EXPORT_CAMERAS, (folder / "cam_#.json", "--frames",
                                                              frames), blend=blend, addons=())
            return subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                  text=True, env=env, timeout=BLENDER_TIMEOUT_S, **as_user)

        completed = export("1-3")
        assert completed.returncode == 1, completed.stdout
        assert (f"export_cameras.py: error: {approved} is not writable (read-only, or another "
                "user's): refusing to replace it") in completed.stdout, completed.stdout
        assert approved.read_text() == "{}\n" and stat.S_IMODE(approved.stat().st_mode) == 0o444
        first = json.loads((folder / "cam_1.json").read_text())  # written before frame 2
        assert "world_to_camera" in first
        assert sorted(p.name for p in folder.glob("*.json")) == [
            "cam_1.json", "cam_2.json", "cam_3.json", "expected.json"], "no temporary file left"
        completed = export("3")
        assert completed.returncode == 1, completed.stdout
        assert f"error: {private} is not writable (read-only, or another user's)" in \
            completed.stdout, completed.stdout
        assert private.read_text() == "{}\n"
        # read-only but already holding the camera: up to date, exit 0
        (folder / "cam_1.json").chmod(0o444)
        again = export("1")
        assert again.returncode == 0, again.stdout
        assert "0 files written, 1 already up to date" in again.stdout
        # a symbolic link is written through, as the CLI writes its outputs:
        # the file it names is made, then replaced; the link stays
        shared = folder / "shared"
        shared.mkdir(mode=0o777)
        shared.chmod(0o777)
        os.symlink(shared / "cam.json", folder / "cam_4.json")
        for written in ("1 files written", "0 files written, 1 already up to date"):
            assert written in export("4").stdout
            assert (folder / "cam_4.json").is_symlink()
            assert "world_to_camera" in json.loads((shared / "cam.json").read_text())
        (shared / "cam.json").write_text("{}\n")
        assert "1 files written" in export("4").stdout
        assert (folder / "cam_4.json").is_symlink() and list(shared.iterdir()) == [
            shared / "cam.json"]
    finally:
        shutil.rmtree(folder)


def test_export_cameras_says_which_frame_has_no_camera(run_blender, tmp_path):
    blend = tmp_path / "none.blend"
    run_blender(SCRIPTS_IN_BLENDER / "animated_camera.py", blend, tmp_path / "unused.json",
                "--no-camera", addon=False)
    completed = run_blender(EXPORT_CAMERAS, tmp_path / "c_#.json", "--frames", "1",
                            check=False, blend=blend)
    assert completed.returncode == 1 and "has no camera at frame 1" in completed.stdout
    assert not list(tmp_path.glob("c_*"))


def test_sequence_redoes_a_preview_older_than_its_exr(hbao_tool, tmp_path):
    """A run without --preview recomputes the EXR and leaves the PNG of the
    run before: a later run with --preview must not take that PNG as up to
    date."""
    folder, sources = sequence_folder(tmp_path)
    run_sequence(hbao_tool, folder, "--radius", "0.5")
    stale = (folder / "ao_0001.png").read_bytes()
    run_tool(hbao_tool, folder / "render_####.exr", "-o", folder / "ao_####.exr",
             "--frames", "1-5", "--no-normals")
    again = run_sequence(hbao_tool, folder)
    assert "is up to date" not in again.stderr
    single = tmp_path / "single.png"
    run_ok(hbao_tool, fixture_path(sources[1]), "-o", tmp_path / "single.exr", "--no-normals",
           "--preview", single)
    fresh = (folder / "ao_0001.png").read_bytes()
    assert fresh == single.read_bytes() and fresh != stale
    assert run_sequence(hbao_tool, folder).stderr.count("is up to date, skipped") == 3


def test_sequence_refuses_an_output_that_is_another_frames_input(hbao_tool, tmp_path):
    for frame in range(1, 11):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"f_{frame}.exr")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    for output in (tmp_path / "f_#0.exr", f"{tmp_path}/./f_#0.exr"):  # by the file
        completed = run_tool(hbao_tool, tmp_path / "f_#.exr", "-o", output, "--frames", "1-10",
                             "--no-normals")
        assert_clean_error(completed, EXIT_USAGE, "-o of frame 1", "is the input of frame 10")
    previews = run_tool(hbao_tool, tmp_path / "f_#.exr", "-o", tmp_path / "ao_#.exr",
                        "--preview", tmp_path / "f_1#.exr", "--frames", "1-12", "--no-normals")
    assert_clean_error(previews, EXIT_USAGE, "--preview of frame 1 ", "is the input of frame 11")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    # A name that only looks like another frame's is no input of this run: a
    # number the input's pattern never writes (f_01.exr: f_# writes frame 1
    # as f_1.exr); a frame not listed (f_10.exr with frames 1-9) is not
    # either, but it is a render, which no frame replaces (the frame fails).
    run_ok(hbao_tool, tmp_path / "f_#.exr", "-o", tmp_path / "f_0#.exr", "--frames", "1-9",
           "--no-normals")
    unlisted = run_tool(hbao_tool, tmp_path / "f_#.exr", "-o", tmp_path / "f_#0.exr",
                        "--frames", "1-9", "--no-normals")
    assert_clean_error(unlisted, EXIT_USAGE, "1 of 9 frames failed: 1", "f_10.exr is a render")
    inputs = [f"f_{frame}.exr" for frame in range(1, 11)]
    assert all((tmp_path / name).read_bytes() == before[name] for name in inputs)


def test_sequence_refuses_an_output_that_links_to_another_frames_input(hbao_tool, tmp_path):
    """An output name that is a symbolic link to another listed frame's
    render or camera file, or a render that is a symbolic link to another
    frame's output name: writing that output would replace the file behind
    the link. The names differ, so only the files' identity shows it:
    refused, nothing written. A hard link is no such case (the rename
    replaces that name only): it runs, the other name keeps its file."""
    camera = camera_path("cycles_float_zip").read_text()
    for frame in (1, 2, 3):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"render_{frame}.exr")
        (tmp_path / f"cam_{frame}.json").write_text(camera)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    def run():
        return run_tool(hbao_tool, tmp_path / "render_#.exr", "-o", tmp_path / "ao_#.exr",
                        "--camera", tmp_path / "cam_#.json", "--frames", "1-3")

    def unchanged():
        return {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.name in before} == before

    for name, target, fragment in (("ao_2.exr", "render_3.exr", "the input of frame 3"),
                                   ("ao_1.exr", "cam_3.json", "the --camera file of frame 3")):
        (tmp_path / name).symlink_to(target)
        assert_clean_error(run(), EXIT_USAGE, fragment)
        assert unchanged()
        os.unlink(tmp_path / name)
    # a folder that is a link: p_3/ is the folder of frame 3's render
    for frame in (1, 2, 3):
        (tmp_path / f"in_{frame}").mkdir()
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}" / "r.exr")
    (tmp_path / "p_2").symlink_to("in_3")
    folders = run_tool(hbao_tool, tmp_path / "in_#" / "r.exr", "-o", tmp_path / "o_#.exr",
                       "--preview", tmp_path / "p_#" / "r.exr", "--frames", "1-3",
                       "--no-normals")
    assert_clean_error(folders, EXIT_USAGE, "--preview of frame 2", "the input of frame 3")
    assert (tmp_path / "in_3" / "r.exr").read_bytes() == before["render_3.exr"]
    # render_3.exr a link to frame 2's output name, not written yet (directly,
    # through a chain, or both links to one place), then existing
    os.rename(tmp_path / "render_3.exr", tmp_path / "kept.exr")
    for links in ({"render_3.exr": "ao_2.exr"},
                  {"render_3.exr": "mid.exr", "mid.exr": "ao_2.exr"},
                  {"render_3.exr": "x.exr", "ao_2.exr": "x.exr"},
                  {"ao_2.exr": "render_3.exr"}):  # frame 3's render missing: written there
        for name, target in links.items():
            (tmp_path / name).symlink_to(target)
        assert_clean_error(run(), EXIT_USAGE, "-o of frame 2", "the input of frame 3")
        assert not any((tmp_path / name).exists() for name in ("ao_1.exr", "x.exr")), links
        for name in links:
            os.unlink(tmp_path / name)
    os.rename(tmp_path / "kept.exr", tmp_path / "render_3.exr")
    os.unlink(tmp_path / "render_3.exr")
    (tmp_path / "render_3.exr").symlink_to("ao_2.exr")
    shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / "ao_2.exr")
    assert_clean_error(run(), EXIT_USAGE, "-o of frame 2", "the input of frame 3")
    os.unlink(tmp_path / "render_3.exr")
    os.rename(tmp_path / "ao_2.exr", tmp_path / "render_3.exr")
    assert unchanged()
    # A hard link: the run goes on (frames 1 and 3 written); frame 2 alone
    # stops, its output being a render (test below), and nothing changes.
    os.link(tmp_path / "render_3.exr", tmp_path / "ao_2.exr")
    completed = run()
    assert_clean_error(completed, EXIT_USAGE, "1 of 3 frames failed: 2", "ao_2.exr is a render")
    assert "another path" not in completed.stderr and (tmp_path / "ao_3.exr").is_file()
    assert unchanged()
    os.unlink(tmp_path / "ao_2.exr")
    # one render linked as every frame's input (a still): each output is new
    for frame in (1, 2, 3):
        os.unlink(tmp_path / f"render_{frame}.exr")
        (tmp_path / f"render_{frame}.exr").symlink_to(fixture_path("cycles_float_zip"))
    run_ok(hbao_tool, tmp_path / "render_#.exr", "-o", tmp_path / "ao_#.exr", "--camera",
           tmp_path / "cam_#.json", "--frames", "1-3", "--force")


def test_an_output_that_is_a_render_is_never_replaced(hbao_tool, tmp_path):
    """-o 'render_00#0.exr' --frames 1-2 names render_0010.exr and
    render_0020.exr: renders of frames the run does not list (another farm
    task's), which it replaced. An existing -o or --preview with a Depth
    pass and no hbaoSettings (not an hbao output) is refused, in one run
    and in a sequence (a --preview that named a render had replaced it with
    a PNG, exit 0); an hbao output with the passes copied (--keep-input) is
    still replaced."""
    for frame in (1, 2, 10, 20):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"render_{frame:04d}.exr")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    sequence = run_tool(hbao_tool, tmp_path / "render_####.exr", "-o",
                        tmp_path / "render_00#0.exr", "--frames", "1-2", "--no-normals")
    assert_clean_error(sequence, EXIT_USAGE, "2 of 2 frames failed",
                       f"-o {tmp_path / 'render_0010.exr'} is a render")
    single = run_tool(hbao_tool, tmp_path / "render_0001.exr", "-o",
                      tmp_path / "render_0002.exr", "--no-normals")
    assert_clean_error(single, EXIT_USAGE, "is a render (it has a Depth pass)")
    previews = run_tool(hbao_tool, tmp_path / "render_####.exr", "-o", tmp_path / "ao_####.exr",
                        "--preview", tmp_path / "render_00#0.exr", "--frames", "1-2",
                        "--no-normals")
    assert_clean_error(previews, EXIT_USAGE, "2 of 2 frames failed",
                       f"--preview {tmp_path / 'render_0020.exr'} is a render")
    preview = run_tool(hbao_tool, tmp_path / "render_0001.exr", "-o", tmp_path / "ao.exr",
                       "--preview", tmp_path / "render_0002.exr", "--no-normals")
    assert_clean_error(preview, EXIT_USAGE, "--preview", "is a render (it has a Depth pass)")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    kept = tmp_path / "kept.exr"
    for _ in range(2):  # written, then replaced by the same run
        run_ok(hbao_tool, tmp_path / "render_0001.exr", "-o", kept, "--keep-input",
               "--no-normals")


def acl_text(path):
    """getfacl's lines for `path` without its name: the ACL and its mask."""
    completed = subprocess.run(["getfacl", "--omit-header", "--absolute-names", str(path)],
                               capture_output=True, text=True, check=True)
    return completed.stdout


@pytest.mark.parametrize("tmpfile", ["1", "0"])
def test_outputs_get_a_new_files_permissions_and_keep_an_existing_ones(
        hbao_tool, tmp_path, tmpfile):
    """A new output has the permissions the kernel gives a new file: the
    umask, or the folder's default ACL (a farm's shared folder granting a
    group write access). The tool worked the mode out itself (0666 and the
    umask) and set it, which took the ACL's group write access away (a
    review found it). An existing output keeps its own permissions (it was
    reset to the umask's). Both ways of making the temporary file
    (O_TMPFILE, and named files: HBAO_TMPFILE=0)."""
    env = dict(os.environ, HBAO_TMPFILE=tmpfile)
    source, camera = fixture_path("cycles_float_zip"), tmp_path / "cam.json"
    shutil.copyfile(FIXTURES / "cycles_float_zip.camera.json", camera)

    def compute(output, *more):
        completed = subprocess.run(
            [str(hbao_tool), str(source), "-o", str(output), "--preview",
             str(output.with_suffix(".png")), "--camera", str(camera), *more],
            capture_output=True, text=True, timeout=TOOL_TIMEOUT_S, env=env,
            preexec_fn=lambda: os.umask(0o027))
        assert completed.returncode == 0, completed.stderr

    compute(tmp_path / "new.exr")
    for made in (tmp_path / "new.exr", tmp_path / "new.png"):
        assert stat.S_IMODE(made.stat().st_mode) == 0o640, made
    shared = tmp_path / "shared"
    shared.mkdir()
    subprocess.run(["setfacl", "-m", "g:users:rwx", "-d", "-m", "g:users:rwx", str(shared)],
                   check=True)
    reference = shared / "reference"
    reference.write_bytes(b"")  # as any program creates a file there (open, 0666)
    assert "group:users:rwx" in acl_text(reference)
    compute(shared / "ao.exr")
    for made in (shared / "ao.exr", shared / "ao.png"):
        assert acl_text(made) == acl_text(reference), made
    os.chmod(tmp_path / "new.exr", 0o600)  # made private: stays private when replaced
    os.chmod(tmp_path / "new.png", 0o604)
    compute(tmp_path / "new.exr", "--radius", "0.3")
    assert stat.S_IMODE((tmp_path / "new.exr").stat().st_mode) == 0o600
    assert stat.S_IMODE((tmp_path / "new.png").stat().st_mode) == 0o604
    assert leftover_temporary_files(tmp_path) == [] and leftover_temporary_files(shared) == []


def test_where_an_unnamed_file_cannot_be_named_a_named_one_is_written(hbao_tool, tmp_path):
    """A file system or sandbox may allow O_TMPFILE and refuse linking the
    file to a name (linkat): the tool learns it before the work and makes a
    named temporary instead. Since a94eeb4 that path kept the closed
    unnamed file's descriptor and wrote into it ("Bad file descriptor",
    exit 1: a re-read of the change found it). linkat is refused here by a
    preloaded shim, compiled for the test."""
    shim = tmp_path / "no_linkat.c"
    shim.write_text("#include <errno.h>\n"
                    "int linkat(int a, const char *b, int c, const char *d, int e) {\n"
                    "    (void)a; (void)b; (void)c; (void)d; (void)e;\n"
                    "    errno = EPERM;\n"
                    "    return -1;\n"
                    "}\n")
    library = tmp_path / "no_linkat.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-o", str(library), str(shim)], check=True)
    out = tmp_path / "out"
    out.mkdir()
    for preview in ((), ("--preview", out / "ao.png")):
        completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", out / "ao.exr",
                             "--no-normals", *preview,
                             env=dict(os.environ, LD_PRELOAD=str(library)))
        assert completed.returncode == 0, completed.stderr
        assert "AO" in channels_by_name(info(hbao_tool, out / "ao.exr"))
        assert leftover_temporary_files(out) == []
    assert (out / "ao.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_an_output_its_user_may_not_write_is_not_replaced(hbao_tool):
    """An existing output the user may not write (an approved frame made
    read-only) is refused, as open() for writing (and Blender's own render
    output) would refuse it; the rename replaced it, its folder being
    writable. Run as another user (nobody) where the tests run as root,
    whom no permission stops."""
    folder = Path(tempfile.mkdtemp(prefix="hbao-readonly-"))  # nobody reaches it, not tmp_path
    try:
        folder.chmod(0o777)
        shutil.copyfile(fixture_path("cycles_float_zip"), folder / "in.exr")
        shutil.copyfile(FIXTURES / "cycles_float_zip.camera.json", folder / "cam.json")
        for name in ("in.exr", "cam.json"):
            (folder / name).chmod(0o644)
        approved = folder / "ao.exr"
        approved.write_bytes(b"approved")
        approved.chmod(0o444)
        as_user = {"user": 65534} if os.geteuid() == 0 else {}
        for tmpfile in ("1", "0"):
            for preview in ((), ("--preview", folder / "ao.exr")):
                arguments = (["-o", approved] if not preview
                             else ["-o", folder / "other.exr", *preview])
                completed = subprocess.run(
                    [str(hbao_tool), str(folder / "in.exr"), *map(str, arguments), "--camera",
                     str(folder / "cam.json")], capture_output=True, text=True,
                    timeout=TOOL_TIMEOUT_S, env=dict(os.environ, HBAO_TMPFILE=tmpfile),
                    **as_user)
                assert_clean_error(completed, EXIT_RUNTIME, f"{approved} is not writable",
                                   "refusing to replace it")
                assert approved.read_bytes() == b"approved"
                assert stat.S_IMODE(approved.stat().st_mode) == 0o444
                left = sorted(p.name for p in folder.iterdir())
                assert left == ["ao.exr", "cam.json", "in.exr"]
    finally:
        shutil.rmtree(folder)


def test_sequence_refuses_outputs_that_are_another_frames_or_its_own(hbao_tool, tmp_path):
    """A frame's preview that is another frame's output (-o 'o_#.exr'
    --preview 'o_#0.exr': frame 1's PNG and frame 10's EXR would replace each
    other), or each frame's preview its own output by another name: refused,
    nothing written."""
    for frame in (1, 2, 10):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}.exr")
    before = sorted(p.name for p in tmp_path.iterdir())
    for preview in (tmp_path / "o_#0.exr", f"{tmp_path}/./o_#0.exr"):  # by the file, not the name
        crossed = run_tool(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "o_#.exr",
                           "--preview", preview, "--frames", "1-2,10", "--no-normals")
        assert_clean_error(crossed, EXIT_USAGE, "--preview of frame 1 ", "is the -o of frame 10")
    own = run_tool(hbao_tool, tmp_path / "in_#.exr", "-o", tmp_path / "x_#.exr", "--preview",
                   f"{tmp_path}/./x_#.exr", "--frames", "1-2", "--no-normals")
    assert own.returncode == EXIT_USAGE and own.stderr.count("name the same file") == 2, own.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize("arguments, fragment", [
    (["in_####.exr", "-o", "ao.exr", "--frames", "1-3"], "-o (ao.exr) needs a '#'"),
    (["in.exr", "-o", "ao_#.exr", "--frames", "1-3"], "the input (in.exr) needs a '#'"),
    (["in_#.exr", "-o", "ao_#.exr", "--preview", "p.png", "--frames", "1"], "--preview"),
    (["in_#.exr", "-o", "ao_#.exr", "--frames", "3-1"], "--frames"),
    (["in_#.exr", "-o", "ao_#.exr", "--frames", "-1"], "--frames"),
    (["in_#.exr", "-o", "ao_#.exr", "--frames", "1-2,"], "--frames"),
    (["in_#.exr", "-o", "ao_#.exr", "--frames", "1-5,5-7"], "no frame twice"),
    (["in_#.exr", "-o", "ao_#.exr", "--frames", "1-2", "--jobs", "0"], "--jobs"),
    (["in_#.exr", "-o", "ao_#.exr", "--frames", "1-2", "-j0"], "--jobs"),  # as getopt reads it
    (["in_#.exr", "-o", "ao_#.exr", "--frames", "1-40", "--frames", "3"],
     "--frames is given twice"),
    (["in.exr", "-o", "ao.exr", "--jobs", "2"], "go with --frames"),
    (["in.exr", "-o", "ao.exr", "--force"], "go with --frames"),
    (["--info", "in_#.exr", "--frames", "1"], "drop --frames"),
    # flags that do nothing with --info were accepted silently
    (["--info", "in.exr", "--layer", "Back"], "takes only --json: drop --layer"),
    (["--info", "in.exr", "--json", "-j", "2"], "takes only --json: drop -j"),
    (["--info", "in.exr", "--radius", "-1"], "takes only --json: drop --radius"),
    (["in.exr", "--keep-input", "--info"], "takes only --json: drop --keep-input"),
    (["--info", "in.exr", "--threads=2", "--force"], "takes only --json: drop --threads=2"),
    # "-" is no file name here (it made a file called "-")
    (["in.exr", "-o", "-"], '-o is "-": give /dev/stdout'),
    (["in.exr", "-o", "ao.exr", "--preview", "-"], '--preview is "-"'),
    (["-", "-o", "ao.exr"], 'the input is "-"'),
])
def test_bad_sequence_flags_are_usage_errors(hbao_tool, tmp_path, arguments, fragment):
    completed = run_tool(hbao_tool, *arguments)
    assert_clean_error(completed, EXIT_USAGE, fragment)


def test_a_frame_pattern_without_frames_gets_a_hint(hbao_tool, tmp_path):
    folder, _ = sequence_folder(tmp_path)
    completed = run_tool(hbao_tool, folder / "render_####.exr", "-o", folder / "ao.exr")
    assert_clean_error(completed, EXIT_RUNTIME, "give --frames")


# --- command line --------------------------------------------------------------

@pytest.mark.parametrize("arguments, fragment", [
    (["--radius", "nan"], "--radius"),
    (["--radius", "0,5"], '--radius: "0,5" is not a finite number (use a decimal point)'),
    (["--radius", "inf"], "--radius"),
    (["--radius", "1e999"], "--radius"),
    (["--radius", "-1"], "--radius"),
    (["--thickness", "-0.5"], "--thickness"),
    (["--thickness", "inf"], "--thickness"),
    (["--radius", ""], "--radius"),
    (["--radius=2x"], "--radius"),
    (["--directions", "abc"], "--directions"),
    (["--directions", "1.5"], "--directions"),
    (["--steps", "99999999999"], "--steps"),
    (["--lens", "0"], "--lens"),
    (["--falloff", "linear"], "--falloff"),
    (["--integration", "ssao"], "--integration"),
    (["--sensor-fit", "auto"], "--sensor-fit"),
    (["--compression", "dwaa"], "--compression"),
    (["--world-to-camera", "1,0,0,0"], "--world-to-camera"),
    (["--world-to-camera", "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 nan"], "--world-to-camera"),
    (["--world-to-camera", "0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0"], "not a camera's matrix"),
    (["--world-to-camera", "1 0 0 0 1 0 0 0 0 0 1 0 0 0 0 1"], "not a camera's matrix"),
    (["--bogus"], "unknown option --bogus"),
    (["-x"], "unknown option -x"),
    (["--half-res=1"], "takes no value"),
    (["--radius"], "needs a value"),
    (["second.exr"], "more than one input"),
    (["--preview", ""], "empty"),
    (["--ao-channel", ""], "empty"),
    (["--ao-channel", "A" * 256], "EXR allows 255"),
    # which one was meant is not known (an exploratory run: the last won)
    (["-o", "second.exr"], "-o (--output) is given twice"),
    (["--layer", "A", "--layer", "B"], "--layer is given twice"),
    (["-hx"], "unknown option -hx"),
    (["-output=x.exr"], "did you mean --output?"),  # not -o with "utput=x.exr"
    (["-radius", "2"], "did you mean --radius?"),
])
def test_bad_flags_are_usage_errors(hbao_tool, tmp_path, arguments, fragment):
    completed = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", tmp_path / "o.exr",
                         *arguments)
    assert_clean_error(completed, EXIT_USAGE, fragment)
    assert not (tmp_path / "o.exr").exists()


def test_short_options_take_their_value_attached(hbao_tool, tmp_path):
    """-oOUT and -j2, as getopt reads them (an exploratory run: -j2 was an
    unknown option while --jobs=2 worked)."""
    for frame in (1, 2):
        shutil.copyfile(fixture_path("cycles_float_zip"), tmp_path / f"in_{frame}.exr")
    run_ok(hbao_tool, tmp_path / "in_#.exr", f"-o{tmp_path}/ao_#.exr", "--frames", "1-2", "-j2",
           "--no-normals")
    assert sorted(p.name for p in tmp_path.glob("ao_*")) == ["ao_1.exr", "ao_2.exr"]


def test_out_of_range_parameters_are_clamped_with_a_warning(hbao_tool, tmp_path):
    """libhbao's hbao_params_resolve decides, for the CLI as for the add-on:
    one warning per clamped value, exit 0, and the AO of the limit values."""
    clamped = compute_ao(hbao_tool, "cycles_float_zip", tmp_path / "clamped.exr",
                         "--steps", "500", "--directions", "0", "--angle-bias", "90",
                         "--blur", "-3", "--strength", "20")
    warnings = [line for line in clamped.stderr.splitlines() if line.startswith("hbao: warning:")]
    assert sorted(warnings) == sorted([
        "hbao: warning: --steps 500 is above the limit 64; using 64",
        "hbao: warning: --directions 0 is below the limit 1; using 1",
        "hbao: warning: --angle-bias 90 is above the limit 60; using 60",
        "hbao: warning: --blur -3 is below the limit 0; using 0",
        "hbao: warning: --strength 20 is above the limit 16; using 16"]), clamped.stderr
    limits = compute_ao(hbao_tool, "cycles_float_zip", tmp_path / "limits.exr",
                        "--steps", "64", "--directions", "1", "--angle-bias", "60",
                        "--blur", "0", "--strength", "16")
    assert limits.stderr == ""
    # Same parameters after clamping, deterministic library: identical AO.
    assert channels_by_name(info(hbao_tool, tmp_path / "clamped.exr"))["AO"] == \
        channels_by_name(info(hbao_tool, tmp_path / "limits.exr"))["AO"]


def test_missing_input_or_output_are_usage_errors(hbao_tool, tmp_path):
    assert_clean_error(run_tool(hbao_tool), EXIT_USAGE, "no input file")
    assert_clean_error(run_tool(hbao_tool, fixture_path("cycles_float_zip")), EXIT_USAGE,
                       "no output file")


def test_all_parameters_are_accepted(hbao_tool, tmp_path):
    output = tmp_path / "ao.exr"
    compute_ao(hbao_tool, "cycles_float_zip", output, "--radius=0.5", "--angle-bias", "5",
               "--directions", "4", "--steps", "3", "--blur", "0", "--blur-sharpness", "2",
               "--half-res", "--falloff", "none", "--integration", "hbao", "--strength", "2",
               "--threads", "1", "--compression", "none", "--sensor-fit", "HORIZONTAL",
               "--shift-x", "0", "--shift-y", "0", "--pixel-aspect-x", "1",
               "--pixel-aspect-y", "1", "--sensor-width", "36", "--sensor-height", "24")
    ao = channels_by_name(info(hbao_tool, output))["AO"]
    assert ao["nonfinite"] == 0 and 0.0 <= ao["min"] <= ao["max"] <= 1.0
    assert info(hbao_tool, output)["compression"] == "none"


def test_radius_zero_gives_no_occlusion(hbao_tool, tmp_path):
    output = tmp_path / "ao.exr"
    compute_ao(hbao_tool, "cycles_float_zip", output, "--radius", "0")
    ao = channels_by_name(info(hbao_tool, output))["AO"]
    assert ao["min"] == ao["max"] == 1.0


def test_ortho_scale_flag_means_orthographic(hbao_tool, tmp_path):
    """ortho_float's JSON says ORTHO; --ortho-scale alone (no JSON) must give the
    same AO as the JSON when the other values match."""
    camera = json.loads(camera_path("ortho_float").read_text())
    assert camera["type"] == "ORTHO"
    matrix = " ".join(str(v) for row in camera["world_to_camera"] for v in row)
    compute_ao(hbao_tool, "ortho_float", tmp_path / "json.exr")
    run_ok(hbao_tool, fixture_path("ortho_float"), "-o", tmp_path / "flags.exr",
           "--ortho-scale", repr(camera["ortho_scale"]), "--world-to-camera", matrix,
           "--sensor-width", repr(camera["sensor_width"]),
           "--sensor-height", repr(camera["sensor_height"]),
           "--sensor-fit", camera["sensor_fit"],
           "--shift-x", repr(camera["shift_x"]), "--shift-y", repr(camera["shift_y"]))
    assert channels_by_name(info(hbao_tool, tmp_path / "json.exr"))["AO"] == \
        channels_by_name(info(hbao_tool, tmp_path / "flags.exr"))["AO"]


def test_help_and_version(hbao_tool):
    shown = run_ok(hbao_tool, "--help")
    for flag in ("--radius", "--angle-bias", "--directions", "--steps", "--blur",
                 "--blur-sharpness", "--half-res", "--falloff", "--integration", "--strength",
                 "--threads", "--lens", "--sensor-width", "--sensor-height", "--sensor-fit",
                 "--shift-x", "--shift-y", "--ortho-scale", "--world-to-camera", "--camera",
                 "--keep-input", "--layer", "--preview", "--info", "identity"):
        assert flag in shown.stdout
    version = run_ok(hbao_tool, "--version").stdout
    assert version.startswith("hbao 0.6.0") and "libhbao 0.6.0" in version
    # the kernel this CPU runs, which a farm's nodes may differ in
    assert re.search(r"; horizon search: (AVX-512|AVX2|generic)\)$", version.strip())
    # They win over everything else, a bad value of another flag too.
    for arguments in (["--help", "--radius", "abc"], ["--radius", "abc", "-h"],
                      ["x.exr", "--version", "--help"]):
        assert run_ok(hbao_tool, *arguments).stdout == shown.stdout
    assert run_ok(hbao_tool, "--steps", "0.5", "--version").stdout == version
    # A flag's value that reads like them is a value: no help, no success.
    as_value = run_tool(hbao_tool, fixture_path("cycles_float_zip"), "-o", "out.exr", "--layer",
                        "-h")
    assert_clean_error(as_value, EXIT_RUNTIME, 'no layer "-h"')


def test_info_json_is_valid_utf8_whatever_the_names_hold(hbao_tool, tmp_path):
    """JSON text is UTF-8: a channel name's bytes that are not (EXR names are
    any bytes) come out as U+FFFD, so that a pipeline's parser reads it."""
    depth = np.full((2, 2), 2.0, np.float32)
    data = scanline_exr({"Depth.Z": depth, "Xq": depth, "Yq": depth, "Zq": depth}, 2, 2)
    data = data.replace(b"Xq\0", b"X\xff\0").replace(b"Yq\0", b"Y\xc3\0")
    data = data.replace(b"Zq\0", b"\xc3\xa9\0")  # valid: kept
    source = tmp_path / "names.exr"
    source.write_bytes(data)
    completed = subprocess.run([str(hbao_tool), "--info", "--json", str(source)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               timeout=TOOL_TIMEOUT_S)
    assert completed.returncode == 0, completed.stderr
    names = [c["name"] for c in json.loads(completed.stdout.decode("utf-8"))["channels"]]
    assert sorted(names) == sorted(["Depth.Z", "X\ufffd", "Y\ufffd", "\u00e9"])


def test_names_from_a_file_reach_the_terminal_escaped(hbao_tool, tmp_path):
    """EXR names are any bytes: a layer named with an escape sequence (clear
    the screen, set the window title) or a newline drove the terminal, or
    faked a line, when --info printed it and when an error or warning named
    it. Control characters come out as \\xNN in the text, the messages and
    the warnings; --json escapes them as JSON does."""
    depth = np.full((16, 16), 2.0, np.float32)
    depth[4:8, 4:8] = 1.5
    # long enough (56 bytes) for the warning that Blender before 5.0 cut its Normal pass
    layer = "Evil\x1b[2J\x1b]0;title\x07\nhbao: fake" + "L" * 32
    source = tmp_path / "names.exr"
    source.write_bytes(scanline_exr({f"{layer}.Depth.Z": depth}, 16, 16))
    escaped = "Evil\\x1b[2J\\x1b]0;title\\x07\\x0ahbao: fake"
    text = run_ok(hbao_tool, "--info", source).stdout
    assert escaped in text and "\x1b" not in text and "\x07" not in text, text
    assert not any(line.startswith("hbao: fake") for line in text.splitlines())
    refused = run_tool(hbao_tool, source, "-o", tmp_path / "ao.exr", "--layer", "Other")
    assert_clean_error(refused, EXIT_RUNTIME, escaped)
    assert "\x1b" not in refused.stderr and len(refused.stderr.splitlines()) == 1
    warned = run_ok(hbao_tool, source, "-o", tmp_path / "ao.exr", "--radius", "1")
    assert escaped in warned.stderr and "\x1b" not in warned.stderr, warned.stderr
    described = json.loads(run_ok(hbao_tool, "--info", "--json", source).stdout)
    assert described["layers"] == [layer]
    # C1 controls (U+009B, a terminal's CSI, in UTF-8) and bytes that are no
    # UTF-8 (a raw 0x9b, CSI to an 8-bit terminal) passed (a review); a
    # backslash is escaped too, so that no name reads as an escape; "é" stays
    data = scanline_exr({"C1\u009b2J\\x1b\u00e9q.Depth.Z": depth}, 16, 16)
    source.write_bytes(data.replace(b"q.Depth", b"\x9b.Depth"))
    for arguments in (("--info", source), (source, "-o", tmp_path / "c1.exr", "--layer", "No")):
        completed = subprocess.run([str(hbao_tool)] + [str(a) for a in arguments],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   timeout=TOOL_TIMEOUT_S)
        output = completed.stdout + completed.stderr
        assert b"C1\\xc2\\x9b2J\\x5cx1b\xc3\xa9\\x9b" in output, output
        assert b"\xc2\x9b" not in output and b"\x9b." not in output, output


def test_info_lists_layers_and_types(hbao_tool):
    description = info(hbao_tool, fixture_path("eevee_half"))
    assert description["layers"] == ["ViewLayer"]
    channels = channels_by_name(description)
    assert channels["ViewLayer.Combined.R"]["type"] == "half"
    # EEVEE stores the sky's depth as the largest half float.
    assert channels["ViewLayer.Depth.Z"]["max"] == BACKGROUND_DEPTH
    text = run_ok(hbao_tool, "--info", fixture_path("eevee_half")).stdout
    assert "ViewLayer.Depth.Z" in text and "compression:" in text


# A cropped border render's EXR: display window 192 x 96, data window 64 x 64 at
# column 64, row 16 (a multiple of HBAO's 64-column blocks and 4-row sampling
# pattern, so that both images sample alike).
FULL_SIZE = (192, 96)
DATA_WINDOW = (64, 16, 64, 64)
# The full frame's camera and the crop's differ by float roundings of their view
# numbers (~1e-7); a step offset within that of a pixel boundary rounds to the
# other pixel, and at a crease that moves the pixel's AO. So: most pixels agree
# to 1e-3 (horizon rounding), at most 3 % differ more (test_camera.c's bound).
CROP_AO_TOLERANCE = 1e-3
CROP_AO_MAX_DIFFERING_FRACTION = 0.03


def _wavy_depth(width, height):
    """A wavy surface 4..6 units away: valleys occlude everywhere."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float64)
    return (5.0 + 0.8 * np.sin(x / 5.0) * np.sin(y / 6.0)).astype(np.float32)


def test_a_data_window_gets_the_camera_of_its_crop(hbao_tool, tmp_path):
    """An EXR whose data window is part of its display window (a cropped border
    render) gives the AO the full frame gives at the same pixels: the tool
    crops the camera with libhbao's hbao_camera_crop. A camera that ignored
    the crop would move every position."""
    from hbao import exr_passes
    full_width, full_height = FULL_SIZE
    x0, y0, width, height = DATA_WINDOW
    depth = _wavy_depth(full_width, full_height)
    camera = tmp_path / "camera.json"
    camera.write_text(json.dumps({"type": "PERSP", "lens": 35.0, "shift_x": 0.1,
                                  "shift_y": -0.05}))
    full = tmp_path / "full.exr"
    full.write_bytes(scanline_exr({"Depth.Z": depth}, full_width, full_height))
    crop = tmp_path / "crop.exr"
    crop.write_bytes(scanline_exr({"Depth.Z": depth[y0:y0 + height, x0:x0 + width]}, width,
                                  height, display_window=(0, 0, full_width - 1, full_height - 1),
                                  data_origin=(x0, y0)))
    outputs = {}
    for name, path in (("full", full), ("crop", crop)):
        outputs[name] = tmp_path / f"{name}_ao.exr"
        run_ok(hbao_tool, path, "-o", outputs[name], "--camera", camera, "--radius", "0.2",
               "--blur", "0", "--threads", "1")
    full_ao = exr_passes.read_channels(outputs["full"], ["AO"])["AO"]
    crop_ao = exr_passes.read_channels(outputs["crop"], ["AO"])["AO"]
    assert crop_ao.shape == (height, width)
    # The radius reaches at most 0.2 / (4.2 * 36 / 35 / 192) < 9 pixels (depth >= 4.2):
    # compare the pixels whose samples all lie inside the crop.
    margin = 10
    inside = crop_ao[margin:-margin, margin:-margin]
    same = full_ao[y0 + margin:y0 + height - margin, x0 + margin:x0 + width - margin]
    differing = np.mean(np.abs(inside - same) > CROP_AO_TOLERANCE)
    assert differing <= CROP_AO_MAX_DIFFERING_FRACTION, differing
    assert np.mean(1.0 - same) > 0.05  # there is occlusion to compare


# The camera of the display window DATA_WINDOW of FULL_SIZE under test above's
# full-frame camera (lens 35, sensor 36 fitted to the 192-pixel width, shift
# (0.1, -0.05)), worked out by hand from docs/algorithm.md's crop rule: the
# sensor spans 64 of 192 pixels, 36 * 64 / 192 = 12 mm; the window's left edge
# lies at -96 + 0.1 * 192 + 64 = -12.8 pixels from the view axis, its centre
# at 19.2 = 0.3 * 64; its bottom edge at -48 - 0.05 * 192 + (96 - 16 - 64) =
# -41.6, its centre at -9.6 = -0.15 * 64.
WINDOW_CAMERA = {"type": "PERSP", "lens": 35.0, "sensor_width": 12.0,
                 "sensor_fit": "HORIZONTAL", "shift_x": 0.3, "shift_y": -0.15}


def test_a_data_window_past_the_display_window_is_a_guard_band(hbao_tool, tmp_path):
    """Overscan: a display window (the frame, whose camera is given) inside a
    larger data window. The tool widens the frame's camera to the data window
    (hbao_camera_crop with a negative origin) and computes AO over all of it,
    so the frame's border pixels see the occluders outside the frame: the AO
    equals that of the larger frame rendered with its own camera, while the
    frame alone differs at its borders. The output keeps the input's windows;
    --crop-to-display writes only the frame. --overscan N does the same for
    a plain render widened by N pixels a side (Blender writes no overscan
    windows), given with its own wide camera."""
    from hbao import exr_passes
    full_width, full_height = FULL_SIZE
    x0, y0, width, height = DATA_WINDOW
    depth = _wavy_depth(full_width, full_height)
    full_camera = tmp_path / "full_camera.json"
    full_camera.write_text(json.dumps({"type": "PERSP", "lens": 35.0, "shift_x": 0.1,
                                       "shift_y": -0.05}))
    window_camera = tmp_path / "window_camera.json"
    window_camera.write_text(json.dumps(WINDOW_CAMERA))
    full = tmp_path / "full.exr"
    full.write_bytes(scanline_exr({"Depth.Z": depth}, full_width, full_height))
    display = (0, 0, width - 1, height - 1)
    overscan = tmp_path / "overscan.exr"
    overscan.write_bytes(scanline_exr({"Depth.Z": depth}, full_width, full_height,
                                      display_window=display, data_origin=(-x0, -y0)))
    frame = tmp_path / "frame.exr"
    frame.write_bytes(scanline_exr({"Depth.Z": depth[y0:y0 + height, x0:x0 + width]}, width,
                                   height))
    flags = ("--radius", "0.2", "--blur", "0", "--threads", "1")
    runs = {"full": (full, full_camera), "overscan": (overscan, window_camera),
            "frame": (frame, window_camera)}
    ao = {}
    for name, (path, camera) in runs.items():
        output = tmp_path / f"{name}_ao.exr"
        run_ok(hbao_tool, path, "-o", output, "--camera", camera, *flags)
        ao[name] = exr_passes.read_channels(output, ["AO"])["AO"]
    written = info(hbao_tool, tmp_path / "overscan_ao.exr")
    assert written["data_window"] == info(hbao_tool, overscan)["data_window"]
    assert written["display_window"] == info(hbao_tool, overscan)["display_window"]
    # The same grid as the full frame, all of it: the cameras differ by float
    # roundings only (CROP_AO_* above).
    assert ao["overscan"].shape == (full_height, full_width)
    differing = np.mean(np.abs(ao["overscan"] - ao["full"]) > CROP_AO_TOLERANCE)
    assert differing <= CROP_AO_MAX_DIFFERING_FRACTION, differing
    # Without the band the frame's border pixels miss occluders outside it
    # (the radius reaches up to 9 pixels, see above): a band 9 pixels wide
    # covers 26 % of the frame; here it counts.
    in_frame = ao["full"][y0:y0 + height, x0:x0 + width]
    assert np.mean(np.abs(ao["frame"] - in_frame) > CROP_AO_TOLERANCE) > 0.05

    cropped = tmp_path / "cropped_ao.exr"
    preview = tmp_path / "cropped_ao.png"
    run_ok(hbao_tool, overscan, "-o", cropped, "--camera", window_camera, "--crop-to-display",
           "--preview", preview, "--keep-input", *flags)
    assert info(hbao_tool, cropped)["data_window"] == info(hbao_tool, frame)["data_window"]
    # The same computation, only written in part: bit-identical; copied
    # channels are cropped alike.
    written = exr_passes.read_channels(cropped, ["AO", "Depth.Z"])
    assert np.array_equal(written["AO"], ao["overscan"][y0:y0 + height, x0:x0 + width])
    assert np.array_equal(written["Depth.Z"], depth[y0:y0 + height, x0:x0 + width])
    assert png_header(preview)[:2] == (width, height)

    # --overscan: a plain render widened by a band on every side, with its own
    # (wide) camera, written as its centre frame; the same computation as the
    # full frame's, so bit-identical to its centre.
    band = 16
    centre = tmp_path / "centre_ao.exr"
    run_ok(hbao_tool, full, "-o", centre, "--camera", full_camera, "--overscan", band, *flags)
    assert info(hbao_tool, centre)["data_window"] == [0, 0, full_width - 2 * band - 1,
                                                      full_height - 2 * band - 1]
    assert info(hbao_tool, centre)["display_window"] == info(hbao_tool, centre)["data_window"]
    assert np.array_equal(exr_passes.read_channels(centre, ["AO"])["AO"],
                          ao["full"][band:-band, band:-band])
    assert_clean_error(run_tool(hbao_tool, full, "-o", centre, "--overscan", full_height // 2),
                       1, "leaves no frame")
    assert_clean_error(run_tool(hbao_tool, overscan, "-o", centre, "--overscan", band),
                       1, "must be the display window")
    assert_clean_error(run_tool(hbao_tool, full, "-o", centre, "--overscan", band,
                                "--crop-to-display"), 2, "give one")

    apart = tmp_path / "apart.exr"
    apart.write_bytes(scanline_exr({"Depth.Z": depth}, full_width, full_height,
                                   display_window=display, data_origin=(width, 0)))
    assert_clean_error(run_tool(hbao_tool, apart, "-o", tmp_path / "apart_ao.exr",
                                "--crop-to-display"), 1, "does not overlap")


def test_thickness_lets_light_pass_behind_a_thin_occluder(hbao_tool, tmp_path):
    """A strip 0.3 in front of a wall facing the camera (planar depths 4.7 and
    5): with infinitely thick occluders (the default) the strip darkens the
    wall beside it; --thickness 0.15 makes it a plate wholly in front of the
    wall, and the wall is a bare plane again: AO 1 (to 1e-4, test_ao.c's
    bound for a plane)."""
    from hbao import exr_passes
    width, height = 96, 64
    depth = np.full((height, width), 5.0, np.float32)
    depth[:, 40:56] = 4.7
    source = tmp_path / "strip.exr"
    source.write_bytes(scanline_exr({"Depth.Z": depth}, width, height))
    ao = {}
    for name, extra in (("thick", ()), ("thin", ("--thickness", "0.15"))):
        output = tmp_path / f"{name}.exr"
        run_ok(hbao_tool, source, "-o", output, "--radius", "0.8", "--blur", "0", *extra)
        ao[name] = exr_passes.read_channels(output, ["AO"])["AO"]
    wall = depth == 5.0
    assert ao["thick"][wall].min() < 0.9
    assert ao["thin"][wall].min() == pytest.approx(1.0, abs=1e-4)


def test_back_layer_lets_light_pass_behind_a_thin_occluder(hbao_tool, tmp_path, native):
    """A strip 0.7 in front of a wall, with a second view layer holding the
    back faces: the strip is 0.1 thick (back depth 4.4; the library takes
    it as at least half the radius thick, to 4.7), the wall has no back face
    (0). With --back-layer light passes between strip and wall, so the wall
    beside the strip gets lighter, and the AO is exactly the library's
    (hbao_compute_layers through the binding); the back layer must differ
    from the front one, and a missing one is an error."""
    from hbao import exr_passes
    width, height = 96, 64
    depth = np.full((height, width), 5.0, np.float32)
    depth[:, 40:56] = 4.3
    back = np.where(depth < 5.0, np.float32(4.4), np.float32(0.0)).astype(np.float32)
    source = tmp_path / "strip_layers.exr"
    layers = {"Front.Depth.Z": depth, "BackFaces.Depth.Z": back}
    source.write_bytes(scanline_exr(layers, width, height))
    flags = ("--radius", "0.8", "--blur", "0", "--threads", "1", "--layer", "Front")
    ao = {}
    for name, extra in (("front", ()), ("layers", ("--back-layer", "BackFaces"))):
        output = tmp_path / f"{name}.exr"
        run_ok(hbao_tool, source, "-o", output, *flags, *extra)
        ao[name] = exr_passes.read_channels(output, ["AO"])["AO"]
    wall = depth == 5.0
    print("darkest wall pixel: %.4f without the back layer, %.4f with it"
          % (ao["front"][wall].min(), ao["layers"][wall].min()))
    assert ao["front"][wall].min() < 0.9
    assert ao["layers"][wall].min() > ao["front"][wall].min() + 0.05
    params = {"radius": 0.8, "blur_size": 0, "threads": 1}
    expected = native.compute_ao(depth, None, params=params, back_depth=back)
    assert np.array_equal(ao["layers"], expected)
    for layer, fragment in (("Front", "is the layer the AO is computed from"),
                            ("Missing", "Missing")):
        completed = run_tool(hbao_tool, source, "-o", tmp_path / "bad.exr", *flags,
                             "--back-layer", layer)
        assert completed.returncode != 0 and fragment in completed.stderr, completed.stderr


@pytest.mark.parametrize("names, half", [
    (("B", "G", "R", "Z"), ("B", "G", "R", "Z")),
    (("G", "R", "Z"), ("G", "R", "Z")),
    # Z float beside half and float channels
    (("B", "G", "R", "Z"), ("B", "G", "R")),
    (("A", "B", "G", "R", "Z"), ("B", "R")),
])
def test_depth_beside_colour_channels_not_read(hbao_tool, tmp_path, names, half):
    """Z among three or four other channels, only Z read. Half Z among half
    channels: OpenEXRCore 3.1's fast half-to-float unpackers for 3 and 4
    channels wrote the skipped channels through a NULL pointer (the tool
    crashed; found by fuzz_exr_compute). Float Z beside half and float
    channels: the channels not read share one scratch destination, each in
    its own type. The AO must equal that of the same depths stored alone as
    float."""
    from hbao import exr_passes
    width, height = 40, 24
    depth = _wavy_depth(width, height).astype(np.float16).astype(np.float32)
    channels = {name: np.full((height, width), 0.5, np.float32) for name in names}
    channels["Z"] = depth
    mixed = tmp_path / "mixed.exr"
    mixed.write_bytes(scanline_exr(channels, width, height, half=half))
    alone = tmp_path / "alone.exr"
    alone.write_bytes(scanline_exr({"Z": depth}, width, height))
    ao = {}
    for path in (mixed, alone):
        output = tmp_path / f"{path.stem}_ao.exr"
        run_ok(hbao_tool, path, "-o", output, "--radius", "0.2", "--threads", "1")
        ao[path.stem] = exr_passes.read_channels(output, ["AO"])["AO"]
    assert np.array_equal(ao["mixed"], ao["alone"])
    assert np.mean(1.0 - ao["alone"]) > 0.01  # there is occlusion to compare
