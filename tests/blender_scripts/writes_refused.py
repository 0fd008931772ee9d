# SPDX-License-Identifier: GPL-2.0-or-later
"""Runs a step of the add-on where Blender refuses writes and operators
from Python, as it does in every thread while another thread runs a
read-only callback (a draw, Cycles' render): Blender calls a node class's
poll read-only when a node is added, so the step runs in one.

  sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
  from writes_refused import while_writes_refused
"""
import bpy


class _RefusingTree(bpy.types.NodeTree):
    bl_idname = "HBAOTestRefusingTree"
    bl_label = "Writes Refused"
    bl_icon = "NODETREE"


class _RefusingNode(bpy.types.Node):
    bl_idname = "HBAOTestRefusingNode"
    bl_label = "Writes Refused"
    action = None
    outcome = {}

    @classmethod
    def poll(cls, _tree):
        if cls.action is not None:
            action, cls.action = cls.action, None
            scene = bpy.data.scenes[0]
            try:
                scene.frame_current = scene.frame_current
                cls.outcome["error"] = AssertionError("Blender did not refuse the write")
            except AttributeError:
                try:
                    cls.outcome["result"] = action()
                except Exception as error:
                    cls.outcome["error"] = error
        return True


def while_writes_refused(action):
    """action() where Blender refuses writes; its result, or its exception
    raised here. Fails when Blender did not refuse a write there."""
    classes = (_RefusingTree, _RefusingNode)
    for cls in classes:
        bpy.utils.register_class(cls)
    probe = bpy.data.node_groups.new("writes refused", _RefusingTree.bl_idname)
    _RefusingNode.action, _RefusingNode.outcome = action, {}
    try:
        probe.nodes.new(_RefusingNode.bl_idname)
    finally:
        bpy.data.node_groups.remove(probe)
        for cls in reversed(classes):
            bpy.utils.unregister_class(cls)
    if "error" in _RefusingNode.outcome:
        raise _RefusingNode.outcome["error"]
    if "result" not in _RefusingNode.outcome:
        raise AssertionError("Blender did not call the node's poll")
    return _RefusingNode.outcome["result"]
