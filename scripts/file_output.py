# SPDX-License-Identifier: GPL-2.0-or-later
"""The compositor's File Output node in each Blender version, for the
project's scripts and tests (the add-on writes no file through one): where
it writes, and its inputs. blender_scenes.Compositor.file_output uses it."""
import os

# 5.0 types a File Output's items; its socket types by the linked output's.
_ITEM_TYPES = {"VALUE": "FLOAT", "RGBA": "RGBA", "VECTOR": "VECTOR"}
# 3.4 does not free the storage of a File Output input removed from Python
# (Blender prints "Not freed memory blocks" as it quits): the node's first
# input stays, marked spare, and the first new input takes it over.
_SPARE_INPUT = "hbao_spare_input"


def set_path(node, folder, prefix):
    """Where `node` writes: FOLDER/PREFIX<frame, 4 digits>.<ext>. Before 5.0
    the frame is appended to a path without '#'; 5.0 needs the '#'."""
    if "#" not in prefix:
        prefix += "####"
    if hasattr(node, "directory"):  # 5.0
        node.directory = folder
        node.file_name = prefix
    else:
        node.base_path = os.path.join(folder, prefix)


def clear_inputs(node):
    """Leave `node` with no input of its own (before 5.0, one spare input
    that new_input takes over)."""
    if hasattr(node, "file_output_items"):  # 5.0
        node.file_output_items.clear()
        return
    while len(node.file_slots) > 1:
        node.file_slots.remove(node.inputs[-1])
    node[_SPARE_INPUT] = len(node.file_slots) == 1


def new_input(node, name, socket):
    """A new input of `node` called `name`, typed like `socket` (5.0 types
    its items), its file and its layer called `name` too; returns it."""
    if hasattr(node, "file_output_items"):  # 5.0
        node.file_output_items.new(_ITEM_TYPES.get(socket.type, "RGBA"), name)
        return node.inputs[name]
    if node.get(_SPARE_INPUT):
        del node[_SPARE_INPUT]
        node.file_slots[0].path = name
        node.layer_slots[0].name = name
        node.inputs[0].name = name
        return node.inputs[0]
    node.file_slots.new(name)
    # the new input is the last: by name, 4.5 would find the first (whose
    # identifier stays "Image" when its name is another)
    return node.inputs[-1]
