# SPDX-License-Identifier: GPL-2.0-or-later
"""A value socket's animation and driver, kept across a rebuild of its
node's group: bpy 5.3 deletes a socket's F-Curve and driver with the group
socket that the rebuild of the shared group removes (4.5 and 5.0 keep them),
node_group.py. Everything an artist sets is kept: the keyframes with every
setting (interpolation, easing and its Back/Elastic parameters, handles,
keyframe type), each curve's own settings (extrapolation, mute, lock, ...)
and modifiers (Cycles, Noise, Generator, Envelope, ...), the driver's
expression and variables with their targets."""
import bpy

from . import compat

# Set when the curve is made, or selection state: not the artist's settings.
_CURVE_SKIPPED = {"data_path", "array_index", "select"}
_KEY_SKIPPED = {"co", "co_ui", "handle_left", "handle_right", "handle_left_type",
                "handle_right_type", "select_control_point", "select_left_handle",
                "select_right_handle"}
_MODIFIER_SKIPPED = {"type", "active", "is_valid", "show_expanded"}


def _settings(struct, skipped):
    """{identifier: value} of struct's writable plain properties (JSON)."""
    settings = {}
    for prop in struct.bl_rna.properties:
        if prop.is_readonly or prop.identifier in skipped or prop.identifier == "rna_type" \
                or prop.type in {"POINTER", "COLLECTION"}:
            continue
        value = getattr(struct, prop.identifier)
        if prop.type == "ENUM" and getattr(prop, "is_enum_flag", False):
            value = sorted(value)
        elif not isinstance(value, str) and hasattr(value, "__len__"):
            value = list(value)
        settings[prop.identifier] = value
    return settings


def _apply(struct, settings):
    """_settings() back onto struct; a setting this Blender lacks or refuses
    is left as it is (a file saved by another version)."""
    for identifier, value in settings.items():
        try:
            setattr(struct, identifier, set(value) if isinstance(getattr(
                struct, identifier), set) else value)
        except (AttributeError, TypeError, ValueError):
            pass


def _key_state(key):
    return {"co": list(key.co), "handle_left_type": key.handle_left_type,
            "handle_right_type": key.handle_right_type, "handle_left": list(key.handle_left),
            "handle_right": list(key.handle_right), "settings": _settings(key, _KEY_SKIPPED)}


def _modifier_state(modifier):
    state = {"type": modifier.type, "settings": _settings(modifier, _MODIFIER_SKIPPED)}
    points = getattr(modifier, "control_points", None)  # Envelope
    if points is not None:
        state["control_points"] = [_settings(point, ()) for point in points]
    return state


def _curve_state(fcurve):
    return {"curve": _settings(fcurve, _CURVE_SKIPPED),
            "keys": [_key_state(key) for key in fcurve.keyframe_points],
            "modifiers": [_modifier_state(modifier) for modifier in fcurve.modifiers]}


def _target_state(target):
    ident = target.id
    return {"settings": _settings(target, ()),
            "id": None if ident is None else [ident.name, getattr(ident.library, "filepath", None)]}


def _driver_state(fcurve):
    driver = fcurve.driver
    state = _curve_state(fcurve)
    state["driver"] = {"settings": _settings(driver, ()), "variables": [
        {"name": variable.name, "type": variable.type,
         "targets": [_target_state(target) for target in variable.targets]}
        for variable in driver.variables]}
    return state


def driver_fcurve(id_data, path):
    """The driver of `path` of `id_data`, or None."""
    animation = getattr(id_data, "animation_data", None)
    return animation.drivers.find(path) if animation is not None else None


def saved(socket):
    """What animates a one-value socket, as JSON-ready data: {"animation":
    its F-Curve, "driver": its driver}, each where it has one ({} for none):
    an F-Curve as {"curve": its settings, "keys": [keyframe], "modifiers":
    [modifier]}, a driver's with "driver": its expression and variables."""
    if hasattr(socket.default_value, "__len__"):
        return {}
    path = socket.path_from_id("default_value")
    state = {}
    fcurve = compat.find_fcurve(socket.id_data, path)
    if fcurve is not None:
        state["animation"] = _curve_state(fcurve)
    driven = driver_fcurve(socket.id_data, path)
    if driven is not None:
        state["driver"] = _driver_state(driven)
    return state


def _restore_key(point, key):
    _apply(point, key.get("settings", {}))
    point.handle_left_type = key["handle_left_type"]
    point.handle_right_type = key["handle_right_type"]
    point.handle_left, point.handle_right = key["handle_left"], key["handle_right"]


def _restore_modifier(fcurve, state):
    try:
        modifier = fcurve.modifiers.new(state["type"])
    except (TypeError, ValueError, RuntimeError):
        return  # a modifier type this Blender does not have
    _restore_envelope(modifier, state.get("control_points", []))
    _apply(modifier, state.get("settings", {}))


def _restore_envelope(modifier, saved_points):
    """An Envelope's control points: added at their frames, their bounds set
    in one foreach_set per bound, never through a point's own properties:
    Blender runs the modifier's update for those with the point as the
    modifier, reading past the point's memory (a crash now and then: bpy 5.3
    crashed at `point.min = ...` in 3 runs of 100)."""
    if not saved_points or not hasattr(modifier, "control_points"):
        return
    by_frame = {}
    for point in saved_points:
        frame = point.get("frame")
        if isinstance(frame, (int, float)) and frame not in by_frame:
            by_frame[frame] = point
            modifier.control_points.add(frame)
    points = modifier.control_points
    for bound in ("min", "max"):
        values = [by_frame.get(point.frame, {}).get(bound, getattr(point, bound))
                  for point in points]
        try:
            points.foreach_set(bound, values)
        except (AttributeError, TypeError, ValueError):
            pass  # a bound this Blender lacks or refuses: left as added


def _restore_curve(fcurve, state):
    """An F-Curve's settings, keyframes (those it lacks inserted, those it
    has beyond them removed: 5.3's driver_add makes (0, 0) and (1, 1)) and
    modifiers (in place of any it has) as _curve_state() saved them."""
    _apply(fcurve, state.get("curve", {}))
    saved_frames = {key["co"][0] for key in state.get("keys", [])}
    for frame in [point.co[0] for point in fcurve.keyframe_points]:
        if frame not in saved_frames:
            point = next(point for point in fcurve.keyframe_points if point.co[0] == frame)
            fcurve.keyframe_points.remove(point)
    frames = {point.co[0] for point in fcurve.keyframe_points}
    for key in state.get("keys", []):
        if key["co"][0] not in frames:
            fcurve.keyframe_points.insert(*key["co"])
    by_frame = {key["co"][0]: key for key in state.get("keys", [])}
    for point in fcurve.keyframe_points:
        key = by_frame.get(point.co[0])
        if key is not None:
            _restore_key(point, key)
    for modifier in list(fcurve.modifiers):
        fcurve.modifiers.remove(modifier)
    for modifier in state.get("modifiers", []):
        _restore_modifier(fcurve, modifier)


def _id_named(id_type, name, library):
    """The data-block of type id_type (an ID's id_type) called name, from
    library (a file path) or the file itself, or None."""
    for attribute in dir(bpy.data):
        collection = getattr(bpy.data, attribute, None)
        if not isinstance(collection, bpy.types.bpy_prop_collection):
            continue
        found = collection.get((name, library) if library else name)
        if found is not None and getattr(found, "id_type", None) == id_type:
            return found
    return None


def _restore_driver(fcurve, state):
    driver, saved_driver = fcurve.driver, state.get("driver", {})
    _apply(driver, saved_driver.get("settings", {}))
    for variable in list(driver.variables):
        driver.variables.remove(variable)
    for saved_variable in saved_driver.get("variables", []):
        variable = driver.variables.new()
        variable.name, variable.type = saved_variable["name"], saved_variable["type"]
        for target, saved_target in zip(variable.targets, saved_variable["targets"]):
            settings = saved_target.get("settings", {})
            _apply(target, {"id_type": settings["id_type"]} if "id_type" in settings else {})
            if saved_target.get("id"):
                found = _id_named(target.id_type, *saved_target["id"])
                if found is not None:
                    target.id = found
            _apply(target, settings)
    _restore_curve(fcurve, state)


def restore(socket, state):
    """The socket's F-Curve and driver again (saved()), each where it is gone."""
    state = state if isinstance(state, dict) else {}
    path = socket.path_from_id("default_value")
    animation = state.get("animation", {})
    if animation.get("keys") and compat.find_fcurve(socket.id_data, path) is None:
        for key in animation["keys"]:
            frame, value = key["co"]
            socket.default_value = int(round(value)) if isinstance(socket.default_value, int) \
                else value
            socket.keyframe_insert("default_value", frame=frame)
        fcurve = compat.find_fcurve(socket.id_data, path)
        if fcurve is not None:
            _restore_curve(fcurve, animation)
    if state.get("driver") and driver_fcurve(socket.id_data, path) is None:
        _restore_driver(socket.driver_add("default_value"), state["driver"])
