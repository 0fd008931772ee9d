# SPDX-License-Identifier: GPL-2.0-or-later
"""libhbao's hbao_params in the binding: a params dict (enums by name, as
Blender spells them) to the struct and back, and resolve_params(), through
which every front end (node, viewport, benchmark) has its values completed and
clamped by the library's own resolver, hbao_params_resolve. Needs numpy, not bpy."""
import ctypes
import math

import numpy as np

from .native_library import HBAO_SUCCESS, check, load_library
from .native_structs import HBAOParams
from .parameters import FALLOFF_VALUES, INTEGRATION_VALUES, LABELS

#: hbao_params' fields in struct order: the keys a params dict may have.
PARAMETER_NAMES = tuple(name for name, _ in HBAOParams._fields_)
# Enum names as Blender spells them, mapped to the header's values (parameters.py).
ENUM_PARAMETERS = {"falloff": FALLOFF_VALUES, "integration": INTEGRATION_VALUES}


_INT32_RANGE = (-2 ** 31, 2 ** 31 - 1)
_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _int32(value):
    """A whole-number field's value: the nearest integer (a Value node may feed
    7.6), a half up, as Blender rounds a keyframed integer socket (round()
    took 2.5 to 2 and 3.5 to 4: a review's find), kept inside int32 so that
    ctypes cannot wrap it; the library's resolver then applies the field's
    limits."""
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError("is not a number") from None
    if value != value:
        raise ValueError("is not a number")
    if value in (float("inf"), float("-inf")):
        raise ValueError("is infinite")  # as the library refuses it in a float field
    return int(min(max(math.floor(value + 0.5), _INT32_RANGE[0]), _INT32_RANGE[1]))


def params_struct(params):
    """The hbao_params for a params dict: the library's defaults, then the given keys."""
    library = load_library()
    structure = HBAOParams()
    library.hbao_params_default(ctypes.byref(structure))
    for key, value in (params or {}).items():
        if key not in PARAMETER_NAMES:
            raise ValueError(f"unknown HBAO parameter {key!r}; known: {', '.join(PARAMETER_NAMES)}")
        if key in ENUM_PARAMETERS:
            names = ENUM_PARAMETERS[key]
            if isinstance(value, str):
                if value not in names:
                    raise ValueError(f"{key} must be one of {', '.join(names)}, not {value!r}")
                value = names[value]
        if dict(HBAOParams._fields_)[key] is ctypes.c_int32:
            try:
                value = _int32(value)
            except ValueError as error:
                raise ValueError(f"{_label(key)} {error}") from None
        else:
            # Beyond float32's range a finite value would become infinite, which
            # the library refuses: hand it the largest float instead, to clamp.
            value = float(value)
            if abs(value) > _FLOAT32_MAX and value == value and abs(value) != float("inf"):
                value = _FLOAT32_MAX if value > 0 else -_FLOAT32_MAX
        setattr(structure, key, value)
    return structure


def _params_dict(structure):
    result = {name: getattr(structure, name) for name in PARAMETER_NAMES}
    for key, names in ENUM_PARAMETERS.items():
        result[key] = next((n for n, v in names.items() if v == result[key]), result[key])
    result["half_resolution"] = bool(result["half_resolution"])
    return result


def default_params():
    """The library's defaults as a params dict (enums by name)."""
    structure = HBAOParams()
    load_library().hbao_params_default(ctypes.byref(structure))
    return _params_dict(structure)


def _label(key):
    return LABELS.get(key, key.replace("_", " ").capitalize())


def _number(value):
    return f"{value:g}" if isinstance(value, float) else str(value)


def _field_names(bits):
    library = load_library()
    names = []
    for bit in range(32):
        if bits & (1 << bit):
            name = library.hbao_param_field_name(1 << bit)
            names.append(name.decode() if name else f"field {bit}")
    return names


def resolve_params(params=None, warnings=None):
    """`params` (a dict of any PARAMETER_NAMES, enums by name) completed with
    the library's defaults and resolved by hbao_params_resolve, the one place
    where the limits are applied: the dict compute_ao would run with (enums by
    name). Every front end (node, viewport) resolves its values here, so the
    artist is told about exactly the clamps the library makes. Each clamped
    value appends "<Label> <value> is above the limit <limit>; using <limit>"
    (or below) to `warnings`, a list, when given. Raises ValueError naming
    the parameter for what the library refuses: a value that is not a number,
    a negative radius, a background depth not above 0, an unknown name."""
    given = dict(params or {})
    structure = params_struct(given)
    out = HBAOParams()
    fields = ctypes.c_uint32(0)
    result = load_library().hbao_params_resolve(ctypes.byref(structure), ctypes.byref(out),
                                                ctypes.byref(fields))
    if result != HBAO_SUCCESS:
        problems = []
        for key in _field_names(fields.value):
            value = getattr(structure, key)
            if value != value:
                problems.append(f"{_label(key)} is not a number")
            elif key == "background_depth":  # (+infinity is one: nothing is background)
                problems.append(f"{_label(key)} {_number(value)} is not above 0")
            elif value in (float("inf"), float("-inf")):
                problems.append(f"{_label(key)} is infinite")
            elif value < 0 and key in ("radius", "thickness"):
                problems.append(f"{_label(key)} {_number(value)} is negative")
            else:
                problems.append(f"{_label(key)} {_number(value)} is not a valid value")
        if not problems:
            check(result)
        raise ValueError("; ".join(problems))
    resolved = _params_dict(out)
    if warnings is not None:
        for key in _field_names(fields.value):
            asked = given.get(key, getattr(structure, key))
            asked = float(asked) if isinstance(asked, float) else asked
            used = resolved[key]
            side = "below" if float(asked) < float(used) else "above"
            warnings.append(f"{_label(key)} {_number(asked)} is {side} the limit "
                            f"{_number(used)}; using {_number(used)}")
    return resolved
