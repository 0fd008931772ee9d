# SPDX-License-Identifier: GPL-2.0-or-later
"""libhbao_exr (csrc/exr/hbao_exr.h), the add-on's EXR reader, called through
ctypes on EXRs that Blender wrote: its pixels must be exactly what the `hbao`
tool reads (the same OpenEXRCore reader, shared object files), and bad input
must give a result code and a message, never a crash."""
import ctypes
import json
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

from conftest import BLENDER, EXR_LIBRARY, FIXTURES, SCRIPTS, blender_environment

# hbao_exr.h result codes.
SUCCESS = 0
ERROR_INVALID_ARGUMENT = 1
ERROR_FILE_ACCESS = 3
ERROR_FORMAT = 4
ERROR_MISSING_CHANNEL = 5
RESULT_CODES = (0, 1, 2, 3, 4, 5)
MESSAGE_SIZE = 1024  # HBAO_EXR_MESSAGE_SIZE
# Fixture renders: tiny and few samples; the pixel values do not matter, only
# that Blender wrote them. One file as the render hook writes it (32-bit,
# uncompressed), one with many passes, one as artists often save (half float,
# ZIP), two layers (last: tests take it as blender_exrs[-1]).
RENDERS = {
    "hook_like": ["--scene", "corner", "--width", "48", "--height", "32", "--samples", "1",
                  "--codec", "NONE"],
    # As the hook writes a render with an artist's usual passes: a few
    # channels of many are read (exr_stream.h). Wide enough that the passes
    # between Depth and Normal are more than the stream reads along (16 KiB).
    "production_passes": ["--scene", "corner", "--width", "240", "--height", "160",
                          "--samples", "1", "--codec", "NONE", "--production-passes"],
    "half_zip_two_layers": ["--scene", "two_layers", "--width", "40", "--height", "24",
                            "--samples", "1", "--codec", "ZIP", "--half"],
}
THREADS = 4
# cJSON prints a double with 15 significant digits when that reads back
# within DBL_EPSILON relative (else with 17): twice DBL_EPSILON bounds it.
JSON_RELATIVE_TOLERANCE = 2 * np.finfo(np.float64).eps
# Two Cycles renders of one scene hold the same Depth, and Normal passes that
# may differ in the last float bits (samples summed across threads; 6e-8 in
# the B44 twins): far below any decoding error, which is of the values' size.
HALF_TWIN_NORMAL_TOLERANCE = 1e-6


# The add-on imports as a package without Blender.
sys.path.insert(0, str(SCRIPTS.parent / "addon"))
from hbao import exr_passes as exr  # noqa: E402


class ChannelRequest(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("data", ctypes.POINTER(ctypes.c_float)),
                ("pixel_stride", ctypes.c_int32), ("row_stride", ctypes.c_int64)]


@pytest.fixture(scope="module")
def library():
    """The raw C interface, declared here independently of the add-on's binding."""
    if not EXR_LIBRARY.exists():
        pytest.fail(f"{EXR_LIBRARY} missing: build with scripts/test.sh or cmake first")
    lib = ctypes.CDLL(str(EXR_LIBRARY))
    handle_p = ctypes.POINTER(ctypes.c_void_p)
    lib.hbao_exr_open.argtypes = [ctypes.c_char_p, handle_p, ctypes.c_char_p, ctypes.c_int32]
    lib.hbao_exr_size.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int32),
                                  ctypes.POINTER(ctypes.c_int32)]
    lib.hbao_exr_size.restype = None
    lib.hbao_exr_channel_count.argtypes = [ctypes.c_void_p]
    lib.hbao_exr_channel_name.argtypes = [ctypes.c_void_p, ctypes.c_int32]
    lib.hbao_exr_channel_name.restype = ctypes.c_char_p
    lib.hbao_exr_has_channel.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
    lib.hbao_exr_read_channel.argtypes = [ctypes.c_void_p, ctypes.c_char_p,
                                          ctypes.POINTER(ctypes.c_float), ctypes.c_int32,
                                          ctypes.c_int64, ctypes.c_char_p, ctypes.c_int32]
    lib.hbao_exr_read_channels.argtypes = [ctypes.c_void_p, ctypes.POINTER(ChannelRequest),
                                           ctypes.c_int32, ctypes.c_char_p, ctypes.c_int32]
    lib.hbao_exr_close.argtypes = [handle_p]
    lib.hbao_exr_close.restype = None
    lib.hbao_exr_result_message.argtypes = [ctypes.c_int32]
    lib.hbao_exr_result_message.restype = ctypes.c_char_p
    return lib


@pytest.fixture(scope="session")
def blender_exrs(tmp_path_factory, blender_user_scripts):
    """Blender-written EXRs: tests/fixtures/*.exr when present, plus small
    renders made here by scripts/render_passes.py."""
    if BLENDER is None:
        pytest.fail("blender not found: run scripts/setup.sh")
    folder = tmp_path_factory.mktemp("blender_exrs")
    paths = sorted(FIXTURES.glob("*.exr")) if FIXTURES.is_dir() else []
    for name, arguments in RENDERS.items():
        completed = subprocess.run(
            [BLENDER, "-b", "--factory-startup", "-noaudio", "--python",
             str(SCRIPTS / "render_passes.py"), "--", "--out", str(folder / name)] + arguments,
            env=blender_environment(blender_user_scripts), stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT, text=True, timeout=600)
        assert completed.returncode == 0, completed.stdout[-3000:]
        paths.append(folder / f"{name}.exr")
    return paths


def cli_info(hbao_tool, path):
    completed = subprocess.run([str(hbao_tool), "--info", "--json", str(path)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert completed.returncode == 0, completed.stderr
    return json.loads(completed.stdout)


def statistics(values):
    """min, max, mean, finite and non-finite counts as info_command.c computes
    them: in double, the sum running over the finite values in row order
    (np.cumsum adds sequentially, so the sum is bit-identical to the C loop)."""
    values = values.astype(np.float64).reshape(-1)
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return {"min": None, "max": None, "mean": None, "finite": 0,
                "nonfinite": int(values.size)}
    return {"min": float(finite.min()), "max": float(finite.max()),
            "mean": float(np.cumsum(finite)[-1] / finite.size), "finite": int(finite.size),
            "nonfinite": int(values.size - finite.size)}


def open_file(library, path):
    handle = ctypes.c_void_p()
    message = ctypes.create_string_buffer(MESSAGE_SIZE)
    result = library.hbao_exr_open(os.fsencode(path), ctypes.byref(handle), message,
                                   MESSAGE_SIZE)
    return result, handle, message.value.decode()


def test_every_channel_matches_the_cli_exactly(blender_exrs, hbao_tool):
    """Depth.Z, Normal.X/Y/Z and every other channel: the statistics of what
    the binding returns equal `hbao --info`'s exactly (same reader, same
    floats; the tool prints doubles that round-trip)."""
    checked_passes = 0
    for path in blender_exrs:
        info = cli_info(hbao_tool, path)
        names = exr.channel_names(path)
        assert names == [channel["name"] for channel in info["channels"]]
        assert exr.image_size(path) == (info["width"], info["height"])
        channels = exr.read_channels(path, names)
        for channel in info["channels"]:
            values = channels[channel["name"]]
            assert values.shape == (info["height"], info["width"])
            assert values.dtype == np.float32
            measured = statistics(values)
            where = (path, channel["name"])
            assert (measured["finite"], measured["nonfinite"]) == \
                (channel["finite"], channel["nonfinite"]), where
            if channel["min"] is None:
                assert measured["min"] is None, where
                continue
            # min and max are pixel values: exactly the same float32.
            assert np.float32(measured["min"]) == np.float32(channel["min"]), where
            assert np.float32(measured["max"]) == np.float32(channel["max"]), where
            # Same double sum in the same order; only cJSON's printing loses
            # bits (it prints 15 digits when they read back within DBL_EPSILON).
            assert measured["mean"] == pytest.approx(channel["mean"],
                                                     rel=JSON_RELATIVE_TOLERANCE), where
            if channel["name"].endswith((".Depth.Z", ".Normal.X", ".Normal.Y", ".Normal.Z")):
                checked_passes += 1
        # Not all constant: a reader that returned one value everywhere would fail.
        for layer in info["layers"]:
            depth = channels[f"{layer}.Depth.Z"]
            assert depth.min() < depth.max()
    # Both renders have Depth and Normal; the two-layer one in two layers.
    assert checked_passes >= 4 * 3


def test_rows_come_top_row_first(blender_exrs):
    """Statistics cannot see a flipped image; the scene can. The renders look
    at a back wall (world normal horizontal, Z = 0) above a floor (Z = 1): the
    first row returned must be wall, the last floor. 0.1 is far from both."""
    for path in blender_exrs[-len(RENDERS):]:
        names = [name for name in exr.channel_names(path) if name.endswith(".Normal.Z")]
        assert names
        for name, normal_z in exr.read_channels(path, names).items():
            assert abs(normal_z[0].mean()) < 0.1, (path, name)
            assert abs(normal_z[-1].mean() - 1.0) < 0.1, (path, name)


def test_interleaved_groups_equal_separate_planes(blender_exrs):
    path = blender_exrs[-1]
    layers = sorted({name.split(".")[0] for name in exr.channel_names(path)
                     if name.endswith(".Depth.Z")})
    assert len(layers) == 2
    groups = {layer: [f"{layer}.Normal.{axis}" for axis in "XYZ"] for layer in layers}
    groups["depth"] = f"{layers[0]}.Depth.Z"
    interleaved = exr.read_channel_groups(path, groups)
    planes = exr.read_channels(path, [name for layer in layers for name in groups[layer]])
    for layer in layers:
        assert interleaved[layer].shape[2] == 3
        for index, axis in enumerate("XYZ"):
            assert np.array_equal(interleaved[layer][:, :, index],
                                  planes[f"{layer}.Normal.{axis}"])
    assert np.array_equal(interleaved["depth"], exr.read_channels(
        path, [groups["depth"]])[groups["depth"]])


def test_strided_read_fills_only_its_pixels(library, blender_exrs):
    """hbao_exr_read_channel with pixel stride 2 and padded rows writes every
    second float of each row and leaves the rest as it was."""
    path = blender_exrs[0]
    result, handle, message = open_file(library, path)
    assert result == SUCCESS, message
    try:
        width, height = ctypes.c_int32(), ctypes.c_int32()
        library.hbao_exr_size(handle, ctypes.byref(width), ctypes.byref(height))
        width, height = width.value, height.value
        name = next(library.hbao_exr_channel_name(handle, i).decode()
                    for i in range(library.hbao_exr_channel_count(handle))
                    if library.hbao_exr_channel_name(handle, i).endswith(b".Depth.Z"))
        row_stride = 2 * width + 3
        buffer = np.full((height, row_stride), -7.0, dtype=np.float32)
        error = ctypes.create_string_buffer(MESSAGE_SIZE)
        assert library.hbao_exr_read_channel(
            handle, name.encode(), buffer.ctypes.data_as(ctypes.POINTER(ctypes.c_float)), 2,
            row_stride, error, MESSAGE_SIZE) == SUCCESS, error.value
    finally:
        library.hbao_exr_close(ctypes.byref(handle))
    expected = exr.read_channels(path, [name])[name]
    assert np.array_equal(buffer[:, 0:2 * width:2], expected)
    untouched = np.ones(buffer.shape, bool)
    untouched[:, 0:2 * width:2] = False
    assert np.all(buffer[untouched] == -7.0)


def test_missing_channel_is_a_clean_error(library, blender_exrs):
    path = blender_exrs[0]
    result, handle, message = open_file(library, path)
    assert result == SUCCESS, message
    try:
        assert library.hbao_exr_has_channel(handle, b"ViewLayer.Depth.Z") == 1
        assert library.hbao_exr_has_channel(handle, b"NoLayer.Depth.Z") == 0
        assert library.hbao_exr_channel_name(handle, -1) is None
        assert library.hbao_exr_channel_name(
            handle, library.hbao_exr_channel_count(handle)) is None
        out = np.zeros(1 << 16, np.float32)
        requests = (ChannelRequest * 2)(
            ChannelRequest(b"ViewLayer.Depth.Z", out.ctypes.data_as(ctypes.POINTER(
                ctypes.c_float)), 1, 256),
            ChannelRequest(b"NoLayer.Depth.Z", out.ctypes.data_as(ctypes.POINTER(
                ctypes.c_float)), 1, 256))
        error = ctypes.create_string_buffer(MESSAGE_SIZE)
        assert library.hbao_exr_read_channels(handle, requests, 2, error,
                                              MESSAGE_SIZE) == ERROR_MISSING_CHANNEL
        assert b"no channel named NoLayer.Depth.Z" in error.value
        assert not out.any()  # refused before decoding anything
    finally:
        library.hbao_exr_close(ctypes.byref(handle))
    with pytest.raises(KeyError, match="has no channel 'NoLayer.Depth.Z'; it has: .*Depth.Z"):
        exr.read_channels(path, ["ViewLayer.Depth.Z", "NoLayer.Depth.Z"])


def test_bad_requests_are_refused(library, blender_exrs):
    result, handle, message = open_file(library, blender_exrs[0])
    assert result == SUCCESS, message
    out = np.zeros(1 << 16, np.float32)
    data = out.ctypes.data_as(ctypes.POINTER(ctypes.c_float))
    error = ctypes.create_string_buffer(MESSAGE_SIZE)
    name = b"ViewLayer.Depth.Z"
    try:
        for bad in (ChannelRequest(name, data, 0, 64), ChannelRequest(name, data, 1, 0),
                    ChannelRequest(name, data, 1, -64), ChannelRequest(name, None, 1, 64),
                    ChannelRequest(None, data, 1, 64), ChannelRequest(name, data, 1, 1 << 40)):
            assert library.hbao_exr_read_channels(handle, ctypes.byref(bad), 1, error,
                                                  MESSAGE_SIZE) == ERROR_INVALID_ARGUMENT
            assert error.value
        twice = (ChannelRequest * 2)(ChannelRequest(name, data, 1, 64),
                                     ChannelRequest(name, data, 1, 64))
        assert library.hbao_exr_read_channels(handle, twice, 2, error,
                                              MESSAGE_SIZE) == ERROR_INVALID_ARGUMENT
        assert b"requested twice" in error.value
        assert library.hbao_exr_read_channels(None, twice, 1, error,
                                              MESSAGE_SIZE) == ERROR_INVALID_ARGUMENT
        # No message buffer at all is allowed: only the code comes back.
        assert library.hbao_exr_read_channels(handle, twice, 2, None, 0) == \
            ERROR_INVALID_ARGUMENT
    finally:
        library.hbao_exr_close(ctypes.byref(handle))
    assert not out.any()


def _expect_failure(library, path, codes):
    """Opening and reading every channel of `path` fails with one of `codes`
    and a message naming the file; the process survives (no crash)."""
    result, handle, message = open_file(library, path)
    if result == SUCCESS:
        try:
            width, height = ctypes.c_int32(), ctypes.c_int32()
            library.hbao_exr_size(handle, ctypes.byref(width), ctypes.byref(height))
            count = library.hbao_exr_channel_count(handle)
            out = np.zeros((count, height.value, width.value), np.float32)
            requests = (ChannelRequest * count)(*[
                ChannelRequest(library.hbao_exr_channel_name(handle, c),
                               out[c].ctypes.data_as(ctypes.POINTER(ctypes.c_float)), 1,
                               width.value) for c in range(count)])
            error = ctypes.create_string_buffer(MESSAGE_SIZE)
            result = library.hbao_exr_read_channels(handle, requests, count, error,
                                                    MESSAGE_SIZE)
            message = error.value.decode()
        finally:
            library.hbao_exr_close(ctypes.byref(handle))
    else:
        assert handle.value is None  # a failed open hands back no handle
    assert result in codes, (path, result, message)
    assert str(path) in message


def test_truncated_files_give_an_error(library, blender_exrs, tmp_path):
    data = blender_exrs[0].read_bytes()
    # Cut inside the magic number, the header, the offset table, the pixel
    # data and just before the last byte.
    for length in (3, 40, 400, len(data) // 2, len(data) - 1):
        path = tmp_path / f"truncated_{length}.exr"
        path.write_bytes(data[:length])
        _expect_failure(library, path, (ERROR_FORMAT,))
        # The damage is in the last band when several threads decode.
        for threads in (1, 16):
            with pytest.raises(exr.EXRFormatError, match=str(path)):
                exr.read_channels(path, exr.channel_names(blender_exrs[0]), threads=threads)


def test_garbage_and_missing_files_give_an_error(library, blender_exrs, tmp_path):
    rng = np.random.default_rng(2024)
    data = blender_exrs[0].read_bytes()
    cases = {
        "random.exr": rng.integers(0, 256, 4096, dtype=np.uint8).tobytes(),
        "magic_then_random.exr": data[:8] + rng.integers(0, 256, 4096, dtype=np.uint8).tobytes(),
        "empty.exr": b"",
        "text.exr": b"this is not an image\n" * 50,
    }
    for name, content in cases.items():
        path = tmp_path / name
        path.write_bytes(content)
        _expect_failure(library, path, (ERROR_FORMAT,))
    missing = tmp_path / "does_not_exist.exr"
    _expect_failure(library, missing, (ERROR_FILE_ACCESS,))
    with pytest.raises(exr.EXRFileError, match="does_not_exist.exr: cannot open"):
        exr.channel_names(missing)
    _expect_failure(library, tmp_path, (ERROR_FORMAT, ERROR_FILE_ACCESS))  # a folder


def test_invalid_open_arguments_and_double_close(library, blender_exrs):
    message = ctypes.create_string_buffer(MESSAGE_SIZE)
    assert library.hbao_exr_open(os.fsencode(blender_exrs[0]), None, message,
                                 MESSAGE_SIZE) == ERROR_INVALID_ARGUMENT
    handle = ctypes.c_void_p(1234)
    assert library.hbao_exr_open(None, ctypes.byref(handle), message,
                                 MESSAGE_SIZE) == ERROR_INVALID_ARGUMENT
    assert handle.value is None
    result, handle, text = open_file(library, blender_exrs[0])
    assert result == SUCCESS, text
    library.hbao_exr_close(ctypes.byref(handle))
    assert handle.value is None  # the close set the handle back to NULL
    library.hbao_exr_close(ctypes.byref(handle))  # closing twice is harmless
    library.hbao_exr_close(None)
    assert library.hbao_exr_channel_count(None) == 0
    width, height = ctypes.c_int32(5), ctypes.c_int32(5)
    library.hbao_exr_size(None, ctypes.byref(width), ctypes.byref(height))
    assert (width.value, height.value) == (0, 0)


def test_result_messages(library):
    messages = [library.hbao_exr_result_message(code) for code in RESULT_CODES]
    assert all(messages) and len(set(messages)) == len(RESULT_CODES)
    assert library.hbao_exr_result_message(99) == b"unknown result"


def test_any_number_of_decoding_threads_reads_the_same_pixels(blender_exrs):
    """A file is decoded in bands of chunks, one thread each: 1, 2, 3 and 16
    threads give exactly the pixels of one, for every compression Blender
    writes (one row per chunk uncompressed, 16 with ZIP, 32 with PIZ and B44)
    and for multi-part files."""
    banded = 0
    for path in blender_exrs:
        names = exr.channel_names(path)
        one = exr.read_channels(path, names, threads=1)
        for threads in (2, 3, 16):
            several = exr.read_channels(path, names, threads=threads)
            for name in names:
                assert np.array_equal(several[name], one[name], equal_nan=True), \
                    (path, threads, name)
        assert any(one[name].min() < one[name].max() for name in names), path
        banded += exr.image_size(path)[1] > 32  # more than one chunk in every compression
    assert banded >= 3


def test_reads_in_parallel_threads_agree(blender_exrs):
    """Each thread opens its own handle; errors and pixels stay per thread."""
    path = blender_exrs[-1]
    names = exr.channel_names(path)
    reference = exr.read_channels(path, names)
    failures, results = [], []

    def work(index):
        try:
            for _ in range(5):
                results.append(exr.read_channels(path, names))
                with pytest.raises(KeyError):
                    exr.read_channels(path, [f"Missing{index}.Z"])
        except Exception as error:  # reported below, in the test's thread
            failures.append(error)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(THREADS)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not failures
    assert len(results) == THREADS * 5
    for result in results:
        assert all(np.array_equal(result[name], reference[name], equal_nan=True)
                   for name in names)


def _depth_and_normal(path, threads):
    layer = next(name for name in exr.channel_names(path) if name.endswith(".Depth.Z"))[:-8]
    return exr.read_channel_groups(path, {
        "depth": [f"{layer}.Depth.Z"],
        "normal": [f"{layer}.Normal.{axis}" for axis in "XYZ"]}, threads)


def _bytes_read():
    """The bytes this process has read from files so far (every thread's)."""
    with open("/proc/self/io") as io:
        return next(int(line.split()[1]) for line in io if line.startswith("rchar:"))


def _read_counting_bytes(read):
    before = _bytes_read()
    result = read()
    return result, _bytes_read() - before


def test_a_few_channels_of_many_are_what_reading_every_channel_gives(blender_exrs):
    """The hand-over's read of a render with an artist's passes: the file is
    uncompressed, so OpenEXRCore reads only the lines of Depth and the
    interleaved Normal and the stream skips the rest (exr_reader.c,
    part_reads_direct; exr_stream.c): the process reads under a quarter of
    the file (a read of every channel, all of it). The pixels must be exactly
    what a read of every channel gives, on 1 and 3 threads."""
    path = next(path for path in blender_exrs if path.stem == "production_passes")
    names = exr.channel_names(path)
    assert len(names) >= 4 * 4 * 3, names  # Depth and Normal well under a quarter
    layer = next(name for name in names if name.endswith(".Depth.Z"))[:-8]
    size = path.stat().st_size
    every, read = _read_counting_bytes(lambda: exr.read_channels(path, names, threads=1))
    assert read >= size * 0.9, (read, size)
    for threads in (1, 3):
        got, read = _read_counting_bytes(lambda: _depth_and_normal(path, threads))
        assert read < size / 4, (read, size)
        assert np.array_equal(got["depth"], every[f"{layer}.Depth.Z"]), threads
        for index, axis in enumerate("XYZ"):
            assert np.array_equal(got["normal"][:, :, index], every[f"{layer}.Normal.{axis}"])
    assert got["depth"].min() < got["depth"].max()


def test_a_few_channels_among_half_and_float_ones(tmp_path):
    """Uncompressed, one part: float Z and N.X/Y/Z among 24 float and 8 half
    channels that are not read (the stream skips their lines: the process
    reads under a quarter of the file), N.X and N.Z without the N.Y between
    them (a line short enough for the stream to read along, into its
    discard buffer, in the same system call), and half ones read as float
    (OpenEXRCore converts: every line is read). Each value must be the one
    written; a chunk whose size is not its lines' is an error, never other
    pixels."""
    from test_cli import scanline_exr
    # 2100 floats a line: the 24 float channels before N.X are far more than
    # the 16 KiB the stream reads along, N.Y (8.2 KiB) less.
    width, height = 2100, 9
    generator = np.random.default_rng(19)
    channels = {name: generator.uniform(-4, 4, (height, width)).astype(np.float32)
                for name in [f"F{k:02d}" for k in range(24)] + [f"h{k}" for k in range(8)] +
                ["N.X", "N.Y", "N.Z", "Z"]}
    half = [f"h{k}" for k in range(8)]
    for name in half:
        channels[name] = channels[name].astype(np.float16).astype(np.float32)
    path = tmp_path / "wide.exr"
    data = scanline_exr(channels, width, height, half=half)
    path.write_bytes(data)
    groups = {"depth": ["Z"], "normal": ["N.X", "N.Y", "N.Z"], "halves": ["h2", "h5"]}
    for threads in (1, 2):
        got, read = _read_counting_bytes(lambda: exr.read_channel_groups(
            path, {key: groups[key] for key in ("depth", "normal")}, threads))
        assert read < len(data) / 4, (read, len(data))
        assert np.array_equal(got["depth"], channels["Z"])
        for index, name in enumerate(groups["normal"]):
            assert np.array_equal(got["normal"][:, :, index], channels[name])
        got = exr.read_channel_groups(path, {"x": ["N.X"], "z": ["N.Z"]}, threads)
        assert np.array_equal(got["x"], channels["N.X"])
        assert np.array_equal(got["z"], channels["N.Z"])
        got = exr.read_channel_groups(path, {"xz": ["N.X", "N.Z"]}, threads)
        assert np.array_equal(got["xz"], np.stack([channels["N.X"], channels["N.Z"]], axis=-1))
        got = exr.read_channel_groups(path, {"halves": groups["halves"]}, threads)
        for index, name in enumerate(groups["halves"]):
            assert np.array_equal(got["halves"][:, :, index], channels[name])
    # Row 7's chunk says it holds 4 bytes fewer than its lines: refused
    # whatever is read (OpenEXRCore 3.4.15 on refuses it itself).
    table = _offset_table_start(data, height)
    chunk = int.from_bytes(data[table + 8 * 7:table + 8 * 8], "little")
    size = int.from_bytes(data[chunk + 4:chunk + 8], "little")
    corrupt = tmp_path / "corrupt.exr"
    corrupt.write_bytes(data[:chunk + 4] + (size - 4).to_bytes(4, "little") + data[chunk + 8:])
    for read in ({key: groups[key] for key in ("depth", "normal")}, {"halves": groups["halves"]},
                 {name: [name] for name in channels}):
        with pytest.raises(exr.EXRFormatError,
                           match="corrupt chunk at scanline 7|[Mm]ismatch") as raised:
            exr.read_channel_groups(corrupt, read, 1)
        assert raised.value.code == ERROR_FORMAT


def test_more_channels_than_the_stream_gathers_at_once(tmp_path):
    """300 channels, every 7th half: a chunk's direct decode asks for more
    lines than the stream gathers before reading them (256, exr_stream.c),
    so it reads part of the chunk in the middle of the decode. Float
    channels read one per group, every other one, and all of them
    interleaved in one group: each value the one written, on 1 and 2
    threads. A file cut short after it was opened is an error that says so,
    never other pixels."""
    from test_cli import scanline_exr
    width, height = 64, 5
    generator = np.random.default_rng(23)
    names = [f"C{k:03d}" for k in range(300)]
    half = names[::7]
    channels = {name: generator.uniform(-4, 4, (height, width)).astype(np.float32)
                for name in names}
    for name in half:
        channels[name] = channels[name].astype(np.float16).astype(np.float32)
    floats = [name for name in names if name not in half]
    path = tmp_path / "many.exr"
    data = scanline_exr(channels, width, height, half=half)
    path.write_bytes(data)
    for threads in (1, 2):
        got = exr.read_channel_groups(path, {name: [name] for name in floats}, threads)
        for name in floats:
            assert np.array_equal(got[name], channels[name]), (threads, name)
        every_other = floats[::2]
        got = exr.read_channel_groups(path, {name: [name] for name in every_other}, threads)
        for name in every_other:
            assert np.array_equal(got[name], channels[name]), (threads, name)
        got = exr.read_channel_groups(path, {"all": floats}, threads)
        for index, name in enumerate(floats):
            assert np.array_equal(got["all"][:, :, index], channels[name]), (threads, name)
    # Cut inside the last row's chunk, within its first 256 channels' lines:
    # the stream's reads in the middle of the decode come up short, and its
    # message is the one given (OpenEXRCore's own says less).
    table = _offset_table_start(data, height)
    last = height - 1
    chunk = int.from_bytes(data[table + 8 * last:table + 8 * last + 8], "little")
    line_bytes = [width * (2 if name in half else 4) for name in names]
    cut = chunk + 8 + sum(line_bytes[:200]) + 10
    _read_after_cutting(path, floats, cut, (height, width, len(floats)))


def _read_after_cutting(path, names, cut, shape):
    """Open `path`, cut it to `cut` bytes, then read `names` into one array:
    the reader must say the file ended (as the stream does, or as
    OpenEXRCore does where it checks the chunk itself)."""
    array = np.zeros(shape, dtype=np.float32)
    with exr._OpenFile(path) as handle:
        os.truncate(path, cut)
        with pytest.raises(exr.EXRFormatError,
                           match=r"ends at byte \d+, inside its chunk \(truncated while read"
                                 r"|cannot read a chunk \(file truncated"):
            handle.read([(name, array, index) for index, name in enumerate(names)])


def test_a_file_cut_short_after_it_was_opened(tmp_path):
    """Depth and Normal of the hand-over's kind of file, cut inside the last
    row's N.Z after the file was opened (no later chunk's header to find
    the file short): an error that says the file ended, not the pixels of
    whatever the destinations held."""
    from test_cli import scanline_exr
    width, height = 300, 8
    generator = np.random.default_rng(29)
    channels = {name: generator.uniform(-4, 4, (height, width)).astype(np.float32)
                for name in ["A", "B", "G", "R", "N.X", "N.Y", "N.Z", "Z"]}
    path = tmp_path / "cut.exr"
    data = scanline_exr(channels, width, height)
    path.write_bytes(data)
    table = _offset_table_start(data, height)
    chunk = int.from_bytes(data[table + 8 * (height - 1):table + 8 * height], "little")
    n_z = sorted(channels).index("N.Z")
    _read_after_cutting(path, ["N.X", "N.Y", "N.Z", "Z"],
                        chunk + 8 + n_z * width * 4 + 100, (height, width, 4))


def test_binding_says_what_to_do_when_the_library_is_missing(tmp_path, monkeypatch):
    """The add-on's own copy missing: the add-on is incomplete. A path given
    by the variable missing, or a folder: the variable is wrong (a review
    found the first message for both)."""
    monkeypatch.delenv(exr.LIBRARY_ENVIRONMENT_VARIABLE, raising=False)
    monkeypatch.setattr(exr._LIBRARY, "default_path", tmp_path / "lib" / "libhbao_exr.so")
    exr.unload_library()
    try:
        with pytest.raises(exr.EXRLibraryError, match="libhbao_exr not found at .*the add-on is "
                                                      "incomplete.*install_addon.sh"):
            exr.read_channels(tmp_path / "any.exr", ["Z"])
        monkeypatch.setenv(exr.LIBRARY_ENVIRONMENT_VARIABLE, str(tmp_path / "libhbao_exr.so"))
        exr.unload_library()
        with pytest.raises(exr.EXRLibraryError, match="libhbao_exr.so, which HBAO_EXR_LIBRARY "
                                                      "names, does not exist. Point"):
            exr.load_library()
        monkeypatch.setenv(exr.LIBRARY_ENVIRONMENT_VARIABLE, str(tmp_path))
        exr.unload_library()
        with pytest.raises(exr.EXRLibraryError, match="which HBAO_EXR_LIBRARY names, is a "
                                                      "folder, not a file"):
            exr.load_library()
        monkeypatch.setenv(exr.LIBRARY_ENVIRONMENT_VARIABLE, str(tmp_path / "libhbao_exr.so"))
        exr.unload_library()
        (tmp_path / "libhbao_exr.so").write_bytes(b"not a library")
        with pytest.raises(exr.EXRLibraryError, match="could not be loaded"):
            exr.load_library()
    finally:
        exr.unload_library()


def _offset_table_start(data, rows):
    """Byte position of the offset table of an uncompressed single-part
    scanline EXR (one row per chunk): its first entry points just past it."""
    for position in range(8, len(data) - 8):
        if int.from_bytes(data[position:position + 8], "little") == position + 8 * rows:
            return position
    raise AssertionError("no offset table found")


def test_corrupt_offset_tables_never_give_wrong_pixels(library, blender_exrs, tmp_path):
    """Offsets past the end of the file, or every row pointing at the first
    chunk: an error, or (when OpenEXRCore rebuilds the table from the chunks
    themselves) exactly the original pixels; never other data, never a crash."""
    # Uncompressed and single-part: one offset table, one row per chunk.
    original = FIXTURES / "cycles_float_none.exr"
    names = exr.channel_names(original)
    reference = exr.read_channels(original, names)
    _, rows = exr.image_size(original)
    data = original.read_bytes()
    table = _offset_table_start(data, rows)
    first_chunk = data[table:table + 8]
    variants = {"past_the_end": (1 << 62).to_bytes(8, "little") * rows,
                "all_first_chunk": first_chunk * rows,
                "reversed": b"".join(data[table + 8 * r:table + 8 * r + 8]
                                     for r in reversed(range(rows)))}
    for name, new_table in variants.items():
        path = tmp_path / f"{name}.exr"
        path.write_bytes(data[:table] + new_table + data[table + 8 * rows:])
        for threads in (1, 16):
            try:
                channels = exr.read_channels(path, names, threads=threads)
            except exr.EXRFormatError as error:
                assert str(path) in str(error)
                assert error.code == ERROR_FORMAT
                continue
            for channel in names:
                assert np.array_equal(channels[channel], reference[channel],
                                      equal_nan=True), (name, threads)


def test_b44_chunks_stored_uncompressed_read_as_their_zip_twin():
    """cycles_half_b44_tail (64 x 33, half colour depth, B44) and its ZIP twin
    cycles_half_zip_tail are renders of one scene (tests/fixtures/README.md).
    Blender keeps Depth and Normal float, which B44 cannot shrink, so a chunk
    that is mostly float, here the last (one row), is stored uncompressed;
    OpenEXRCore 3.1 ran B44's decoder over it: a depth of 2e-6 and normals of
    5.5 in the last row, read without an error. Depth is the same to the bit
    in both renders; Normal to the last float bit (HALF_TWIN_NORMAL_TOLERANCE)."""
    names = ["ViewLayer.Depth.Z"] + [f"ViewLayer.Normal.{axis}" for axis in "XYZ"]
    b44 = exr.read_channels(FIXTURES / "cycles_half_b44_tail.exr", names)
    zip_twin = exr.read_channels(FIXTURES / "cycles_half_zip_tail.exr", names)
    assert b44[names[0]].shape == (33, 64)
    assert np.array_equal(b44[names[0]], zip_twin[names[0]])
    for name in names[1:]:
        np.testing.assert_allclose(b44[name], zip_twin[name], rtol=0,
                                   atol=HALF_TWIN_NORMAL_TOLERANCE, err_msg=name)
