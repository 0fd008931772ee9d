# SPDX-License-Identifier: GPL-2.0-or-later
"""One parameter contract: the C header (csrc/include/hbao.h) defines the
defaults, limits and enums, csrc/lib/ the blur formulas; every Python table
and GLSL constant that must repeat them is checked here against the C
sources themselves, so a copy cannot drift. Plain pytest: no library, no
Blender. Every comparison is exact: the values are decimal literals in both
languages, and float32 literals compare equal to their float64 parse."""
import ctypes
import re
import sys

import pytest

from conftest import REPO

sys.path.insert(0, str(REPO / "addon"))
from hbao import native, parameters  # noqa: E402
from hbao.viewport import shader_sources  # noqa: E402

HEADER = (REPO / "csrc" / "include" / "hbao.h").read_text()
LIBRARY_SOURCES = {path.name: path.read_text()
                   for pattern in ("*.c", "*.h")
                   for path in sorted((REPO / "csrc" / "lib").glob(pattern))}
# Header limits with no Python copy: the binding passes threads through, and
# the library checks them itself.
UNMIRRORED_MAXIMA = {"THREADS"}
# Blender's names for the header's enumerators where they differ.
BLENDER_ENUMERATOR_NAMES = {"PERSPECTIVE": "PERSP", "ORTHOGRAPHIC": "ORTHO"}
PYTHON_ENUMS = {
    "hbao_falloff": parameters.FALLOFF_VALUES,
    "hbao_integration": parameters.INTEGRATION_VALUES,
    "hbao_projection": parameters.PROJECTION_VALUES,
    "hbao_sensor_fit": parameters.SENSOR_FIT_VALUES,
}
C_FIELD_TYPES = {"float": ctypes.c_float, "int32_t": ctypes.c_int32, "double": ctypes.c_double}


def _number(literal):
    return float(literal.rstrip("f"))


def header_defines(prefix):
    """{NAME: value} of `#define <prefix>NAME <number>` in the header."""
    found = {name: _number(value) for name, value in re.findall(
        rf"#define {prefix}(\w+) (-?[\d.]+(?:e-?\d+)?f?)\s", HEADER)}
    assert found, f"no {prefix}* defines found in hbao.h: has the header changed form?"
    return found


def header_enum(name):
    """{ENUMERATOR without the type's prefix: value} of `typedef enum name`."""
    body = re.search(rf"typedef enum {name} \{{(.*?)\}} {name};", HEADER, re.S)
    assert body, f"enum {name} not found in hbao.h"
    prefix = name.upper() + "_"
    values = {key[len(prefix):]: int(value) for key, value in
              re.findall(rf"({prefix}\w+) = (\d+)", body.group(1))}
    assert values, f"enum {name} has no enumerators with explicit values"
    return values


def header_struct(name):
    """[(field, C type, doc comment)] of `typedef struct name` in field order."""
    body = re.search(rf"typedef struct {name} \{{(.*?)\}} {name};", HEADER, re.S)
    assert body, f"struct {name} not found in hbao.h"
    fields = []
    comment = ""
    for match in re.finditer(r"(/\*\*.*?\*/)|(\w+) (\w+)(\[\d+\])?;(\s*/\*\*<.*?\*/)?",
                             body.group(1), re.S):
        if match.group(1):
            comment = match.group(1)
            continue
        fields.append((match.group(3), match.group(2) + (match.group(4) or ""),
                       comment + (match.group(5) or "")))
        comment = ""
    return fields


def library_pattern(pattern, what):
    """The first match of `pattern` in csrc/lib/*.c and *.h, or a failure naming `what`."""
    for source in LIBRARY_SOURCES.values():
        match = re.search(pattern, source)
        if match:
            return match
    pytest.fail(f"{what} not found in csrc/lib/*.[ch]: the library's form changed; update "
                f"this test's pattern and check the Python copy")


def test_every_default_matches_the_header():
    defaults = header_defines("HBAO_DEFAULT_")
    for name, value in defaults.items():
        assert parameters.DEFAULTS[name.lower()] == value, name
    initializer = re.search(r"#define HBAO_PARAMS_DEFAULT_INITIALIZER(.*?)\}", HEADER, re.S)
    falloff = re.search(r"HBAO_FALLOFF_(\w+)", initializer.group(1)).group(1)
    integration = re.search(r"HBAO_INTEGRATION_(\w+)", initializer.group(1)).group(1)
    assert parameters.DEFAULTS["falloff"] == falloff
    assert parameters.DEFAULTS["integration"] == integration
    numeric = {key for key, value in parameters.DEFAULTS.items() if not isinstance(value, str)}
    assert numeric == {name.lower() for name in defaults}, "a Python default has no header twin"


def test_every_limit_matches_the_header():
    maxima = header_defines("HBAO_MAX_")
    for name, value in maxima.items():
        if name in UNMIRRORED_MAXIMA:
            continue
        assert getattr(parameters, f"MAX_{name}") == value, name
    # The header documents each clamped field's range as "clamped to [low, high]".
    documented = {}
    for field, _type, comment in header_struct("hbao_params"):
        match = re.search(r"[Cc]lamped to \[([^,\]]+), ([^\]]+)\]", comment)
        if match:
            documented[field] = (_number(match.group(1)), _number(match.group(2)))
    documented.pop("threads", None)  # the binding passes it through; no Python limit
    assert documented, "no 'clamped to [low, high]' found in hbao_params' comments"
    assert set(documented) == set(parameters.LIMITS)
    for field, (low, high) in documented.items():
        assert parameters.LIMITS[field][:2] == (low, high), field


def test_every_enum_matches_the_header():
    for name, python_values in PYTHON_ENUMS.items():
        expected = {BLENDER_ENUMERATOR_NAMES.get(key, key): value
                    for key, value in header_enum(name).items()}
        assert python_values == expected, name
    assert native.FALLOFF_NAMES is parameters.FALLOFF_VALUES  # one table, not a copy
    menus = {"falloff": parameters.FALLOFF_ITEMS, "integration": parameters.INTEGRATION_ITEMS}
    for key, items in menus.items():
        assert {item[0] for item in items} == set(PYTHON_ENUMS[f"hbao_{key}"])


@pytest.mark.parametrize("struct_name, structure", [("hbao_params", native.HBAOParams),
                                                    ("hbao_camera", native.HBAOCamera),
                                                    ("hbao_view", native.HBAOView)])
def test_the_bindings_structs_match_the_header(struct_name, structure):
    fields = header_struct(struct_name)
    assert [name for name, _, _ in fields] == [name for name, _ in structure._fields_]
    for (name, c_type, _), (_, ctype) in zip(fields, structure._fields_):
        if c_type.endswith("]"):
            base, count = re.match(r"(\w+)\[(\d+)\]", c_type).groups()
            assert ctype._type_ is C_FIELD_TYPES[base] and ctype._length_ == int(count), name
        else:
            assert ctype is C_FIELD_TYPES[c_type], name


def test_the_blur_formulas_match_the_library():
    radius = library_pattern(r">= (\d+) \? \(([\w.>-]+) - (\d+)\) / (\d+) : 0",
                             "the blur size -> radius rule (b >= 2 ? (b - 1) / 2 : 0)")
    threshold, offset, divisor = (int(radius.group(i)) for i in (1, 3, 4))
    for size in range(parameters.MAX_BLUR_SIZE + 2):
        expected = (size - offset) // divisor if size >= threshold else 0
        assert parameters.blur_kernel_radius(size) == expected, size
    sigma = library_pattern(r"sigma = ([\d.]+)f? \* \(float\)\([\w.>]*radius \+ (\d+)\)",
                            "the blur sigma rule (sigma = a * (radius + b))")
    assert parameters.BLUR_SIGMA_PER_TAP == float(sigma.group(1))
    assert parameters.BLUR_SIGMA_TAP_OFFSET == int(sigma.group(2))
    for kernel_radius in range(1, 33):
        assert parameters.blur_sigma(kernel_radius) == \
            float(sigma.group(1)) * (kernel_radius + int(sigma.group(2)))
    grid = library_pattern(r"grid_blur_radius = s->half_resolution \? \(s->blur_radius \+ (\d+)\) "
                           r"/ (\d+) : s->blur_radius;",
                           "the half grid's blur radius rule (half ? (r + 1) / 2 : r)")
    for kernel_radius in range(parameters.blur_kernel_radius(parameters.MAX_BLUR_SIZE) + 1):
        assert parameters.grid_blur_radius(kernel_radius, half=True) == \
            (kernel_radius + int(grid.group(1))) // int(grid.group(2)), kernel_radius
        assert parameters.grid_blur_radius(kernel_radius, half=False) == kernel_radius
    # The spatial weight has the same Gaussian form in C and GLSL; sigma itself
    # comes into the shader as a uniform (parameters.blur_sigma), never recomputed.
    library_pattern(r"expf\(-\(float\)\(k \* k\) / \(2\.0f \* sigma \* sigma\)\)",
                    "the blur's Gaussian exp(-k^2 / (2 sigma^2))")
    assert "exp(-float(x * x) / (2.0 * sigma * sigma)" in shader_sources.BLUR_FRAGMENT
    assert "sigma =" not in shader_sources.BLUR_FRAGMENT


def _squarings(body):
    """How many times `body` squares: `p * p` and `p *= p`."""
    return len(re.findall(r"(\w+(?:\.f)?) \*=? \1\b", body))


def test_the_blur_falloff_matches_the_library():
    # The blur's weight (csrc/lib/internal_finish.h) is (1 - e / R)^R with
    # R = HBAO_BLUR_FALLOFF_REACH, formed as max(0, base)^16 (hbao_blur_power,
    # by squarings) of base = (1 - NS / R + min(n.c', NS / R)) - (d / sqrt R)^2.
    # The viewport's image comparison cannot tell such a weight from exp(-e)
    # (a mutation back to exp passed its tolerances), so the form is held here:
    # the power is R in C and GLSL, the depth weight is 1 / sqrt(R), and both
    # form the base the same way (test_viewport.py compares the constants).
    header = (REPO / "csrc" / "lib" / "internal_finish.h").read_text()
    reach = float(re.search(r"#define HBAO_BLUR_FALLOFF_REACH ([\d.]+)f", header).group(1))
    depth_weight = float(re.search(r"#define HBAO_BLUR_DEPTH_WEIGHT ([\d.]+)f", header).group(1))
    assert depth_weight ** 2 * reach == 1.0
    assert "#define HBAO_BLUR_NORMAL_WEIGHT (HBAO_BLUR_NORMAL_SHARPNESS / " \
        "HBAO_BLUR_FALLOFF_REACH)" in header
    c_power = re.search(r"float hbao_blur_power\(float base\) \{(.*?)\n\}", header, re.S)
    glsl = shader_sources.BLUR_FRAGMENT
    glsl_power = re.search(r"float blur_power\(float base\)\s*\{(.*?)\n\}", glsl, re.S)
    assert c_power and glsl_power, "the blur's power function not found"
    assert 2 ** _squarings(c_power.group(1)) == 2 ** _squarings(glsl_power.group(1)) == reach
    assert "#define NORMAL_WEIGHT (NORMAL_SHARPNESS / FALLOFF_REACH)" in glsl
    for c_form, glsl_form in [
            ("(scaled < FLT_MAX ? scaled : FLT_MAX) * HBAO_BLUR_DEPTH_WEIGHT",
             "min(sharpness / zc, LARGEST_FLOAT) * DEPTH_WEIGHT"),
            ("c->nx[i] * HBAO_BLUR_NORMAL_WEIGHT", ".xyz * NORMAL_WEIGHT"),
            ("facing < HBAO_BLUR_NORMAL_WEIGHT ? facing : HBAO_BLUR_NORMAL_WEIGHT",
             "min(dot(texelFetch(normal_texture, q, 0).xyz, nc), NORMAL_WEIGHT)"),
            ("(1.0f - HBAO_BLUR_NORMAL_WEIGHT + capped) - difference * difference",
             "(1.0 - NORMAL_WEIGHT + facing) - difference * difference"),
            ("taps->spatial[t] * hbao_blur_power(base)", "spatial * blur_power(base)")]:
        assert c_form in LIBRARY_SOURCES["blur.c"], c_form
        assert glsl_form in glsl, glsl_form


def test_the_upsample_falloff_matches_the_library():
    # The upsample weighs a candidate's depth by the blur's F of
    # (UPSAMPLE_SHARPNESS |zs - z| / z)^2, formed as max(0, 1 - scaled^2)^16
    # with scaled = |zs - z| UPSAMPLE_SHARPNESS / sqrt(R) / z, the factor
    # capped at FLT_MAX; the nearest candidate is the one of least |zs - z|.
    # Held in form, as the blur's is: the viewport's comparison would not
    # tell F from exp(-e).
    header = (REPO / "csrc" / "lib" / "internal_finish.h").read_text()
    assert "#define HBAO_UPSAMPLE_DEPTH_WEIGHT (HBAO_UPSAMPLE_SHARPNESS * " \
        "HBAO_BLUR_DEPTH_WEIGHT)" in header
    glsl = shader_sources.UPSAMPLE_FRAGMENT
    assert shader_sources.FALLOFF in glsl and shader_sources.FALLOFF in \
        shader_sources.BLUR_FRAGMENT, "the blur and the upsample share blur_power"
    assert "#define UPSAMPLE_DEPTH_WEIGHT (UPSAMPLE_SHARPNESS * DEPTH_WEIGHT)" in glsl
    for c_form, glsl_form in [
            ("HBAO_UPSAMPLE_DEPTH_WEIGHT / z;", "UPSAMPLE_DEPTH_WEIGHT / z"),
            ("factor < FLT_MAX ? factor : FLT_MAX",
             "min(UPSAMPLE_DEPTH_WEIGHT / z, LARGEST_FLOAT)"),
            ("gap = fabsf(zs - z)", "gap = abs(zs - z)"),
            ("scaled = gap * factor", "scaled = gap * factor"),
            ("bilinear * hbao_blur_power(1.0f - scaled * scaled)",
             "bilinear * blur_power(1.0 - scaled * scaled)"),
            ("gap < *nearest_gap", "gap < nearest_gap")]:
        assert c_form in LIBRARY_SOURCES["upsample.c"], c_form
        assert glsl_form in glsl, glsl_form


def test_the_glsl_constants_match_the_library():
    defines = shader_sources.AO_DEFINES
    for enum_name in ("hbao_falloff", "hbao_integration"):
        for key, value in header_enum(enum_name).items():
            assert defines[f"{enum_name[5:].upper()}_{key}"] == value, key
    epsilon = library_pattern(r"np_length > ([\d.e-]+)f;",
                              "the normal-in-slice threshold (np_length > eps)")
    assert defines["NORMAL_IN_SLICE_EPSILON"] == float(epsilon.group(1))


def test_one_version_everywhere():
    """The release's version lives in CMakeLists.txt (the library's, its
    soname's), hbao.h, the add-on's bl_info and its extension manifest (which
    package_addon.sh names the zips by): they must agree, and so must the
    oldest Blender in bl_info and in compat.py."""
    cmake = re.search(r"project\(hbao VERSION (\d+)\.(\d+)\.(\d+)",
                      (REPO / "CMakeLists.txt").read_text())
    header = tuple(int(re.search(rf"#define HBAO_VERSION_{part} (\d+)", HEADER).group(1))
                   for part in ("MAJOR", "MINOR", "PATCH"))
    package = (REPO / "addon" / "hbao" / "__init__.py").read_text()
    bl_version = re.search(r'"version": \((\d+), (\d+), (\d+)\)', package)
    manifest = re.search(r'^version = "(\d+)\.(\d+)\.(\d+)"',
                         (REPO / "addon" / "hbao" / "blender_manifest.toml").read_text(), re.M)
    versions = [tuple(int(n) for n in match.groups()) for match in (cmake, bl_version, manifest)]
    assert versions == [header] * 3, (header, versions)
    oldest = re.search(r'"blender": \((\d+), (\d+), (\d+)\)', package).groups()
    compat = (REPO / "addon" / "hbao" / "compat.py").read_text()
    assert f"MIN_SUPPORTED_VERSION = ({', '.join(oldest)})" in compat


def test_the_camera_file_keys_are_the_ones_the_cli_reads():
    """The add-on describes a camera (camera.camera_from_blender: the dict
    the node computes with, and what scripts/export_cameras.py writes for
    the CLI) with the keys csrc/tool/camera_json.c reads; the CLI ignores a
    key it does not know, so a key renamed on one side only would leave the
    CLI on its default, silently (an audit)."""
    import ast
    source = (REPO / "addon" / "hbao" / "camera.py").read_text()
    function = next(node for node in ast.walk(ast.parse(source))
                    if isinstance(node, ast.FunctionDef) and node.name == "camera_from_blender")
    returned = [node.value for node in ast.walk(function)
                if isinstance(node, ast.Return) and isinstance(node.value, ast.Dict)]
    assert len(returned) == 1
    written = {key.value for key in returned[0].keys}
    reader = (REPO / "csrc" / "tool" / "camera_json.c").read_text()
    read = set(re.findall(r'\{"(\w+)", CAMERA_FIELD_', reader))
    read |= set(re.findall(r'read_enum\(root, "(\w+)"', reader))
    read |= set(re.findall(r'const char \*key = "(\w+)";', reader))
    assert written == read, (written - read, read - written)
