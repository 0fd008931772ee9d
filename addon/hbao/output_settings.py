# SPDX-License-Identifier: GPL-2.0-or-later
"""The artist's output settings kept across the add-on's own save of the
Render Result (handover.py sets the output to multilayer EXR for it): what
that save reads, and what a change of format resets, saved before and put
back after, in an order in which each value is valid."""

# Image settings a Render Result's save reads or its change of format
# resets, in their order of restoring ("a.b": b of the struct a). Setting
# file_format resets the linear colour space of the output (4.x, 5.x: the
# artist's override, e.g. Linear Rec.2020, became Linear Rec.709 for the
# frame's own file and in the saved .blend; a review's find).
SAVED_IMAGE_SETTINGS = ("media_type", "file_format", "color_mode", "color_depth", "exr_codec",
                        "use_exr_interleave", "use_preview", "use_zbuffer", "views_format",
                        "color_management", "linear_colorspace_settings.name")


def _owner_and_name(struct, dotted):
    """(the struct that holds `dotted`'s last part, that part), or (None, _)."""
    *path, name = dotted.split(".")
    for part in path:
        struct = getattr(struct, part, None)
    return (struct if struct is not None and hasattr(struct, name) else None), name


# Read only where the output overrides the scene's colour management: 3.4
# keeps no valid linear colour space otherwise, and each read of it logged
# a warning ("current value '0' matches no enum"), four lines each frame.
ONLY_WITH_AN_OVERRIDE = ("linear_colorspace_settings.name",)


def saved_image_settings(settings):
    """[(name, value)] of the ImageFormatSettings `settings` that saving a
    Render Result reads or resets, as this version has them, in restoring
    order."""
    saved = []
    override = getattr(settings, "color_management", "OVERRIDE") == "OVERRIDE"
    for dotted in SAVED_IMAGE_SETTINGS:
        if dotted in ONLY_WITH_AN_OVERRIDE and not override:
            continue
        owner, name = _owner_and_name(settings, dotted)
        if owner is not None:
            saved.append((dotted, getattr(owner, name)))
    return saved


def restore_image_settings(settings, saved):
    """Put back what saved_image_settings() returned, in its order; a value
    that is already so is not set again (setting a format re-derives what
    depends on it)."""
    for dotted, value in saved:
        owner, name = _owner_and_name(settings, dotted)
        if owner is None or getattr(owner, name) == value:
            continue
        try:
            setattr(owner, name, value)
        except (TypeError, ValueError):
            pass  # an enum value not valid for the restored format is re-derived


# FFmpegSettings restored first, in this order; the rest after them.
_FFMPEG_FIRST = ("format", "codec", "audio_codec")


def saved_ffmpeg_settings(render):
    """{name: value} of every plain setting of `render`.ffmpeg (RenderSettings):
    3.4 applies its H.264 preset (a Matroska container, H.264, medium
    quality) whenever file_format becomes FFMPEG without audio, as the
    restore of an artist's movie output does after each hand-over (a
    review's find: QuickTime with PNG frames became a lossy .mkv)."""
    ffmpeg = getattr(render, "ffmpeg", None)
    if ffmpeg is None:
        return {}
    return {prop.identifier: getattr(ffmpeg, prop.identifier)
            for prop in ffmpeg.bl_rna.properties
            if not prop.is_readonly and prop.type in ("BOOLEAN", "INT", "FLOAT", "ENUM", "STRING")
            and not getattr(prop, "is_array", False)}


def restore_ffmpeg_settings(render, saved):
    """Put back what saved_ffmpeg_settings() returned, where it changed."""
    ffmpeg = getattr(render, "ffmpeg", None)
    names = [n for n in _FFMPEG_FIRST if n in saved] + [n for n in saved if n not in _FFMPEG_FIRST]
    for name in names:
        if ffmpeg is None or getattr(ffmpeg, name) == saved[name]:
            continue
        try:
            setattr(ffmpeg, name, saved[name])
        except (TypeError, ValueError):
            pass  # not valid with the restored container: Blender's choice stands
