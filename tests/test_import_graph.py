# SPDX-License-Identifier: GPL-2.0-or-later
"""The add-on's structure: its bpy-free modules import in plain Python (as a
package, without Blender), its import graph has no circle, and no module
grows past the size at which it starts doing several jobs. Plain pytest."""
import ast
import subprocess
import sys

from conftest import REPO

PACKAGE = REPO / "addon" / "hbao"
# What tests, benchmarks and scripts import without Blender.
BPY_FREE_MODULES = ("hbao", "hbao.parameters", "hbao.library_loading", "hbao.native",
                    "hbao.native_structs", "hbao.native_library", "hbao.native_params",
                    "hbao.exr_passes", "hbao.view_files", "hbao.camera",
                    "hbao.guard_geometry", "hbao.timing_line", "hbao.scratch_names",
                    "hbao.render_threads", "hbao.scratch_files", "hbao.stereo_eyes",
                    "hbao.refusal_watch", "hbao.ui_text",
                    "hbao.viewport",
                    "hbao.viewport.projection", "hbao.viewport.shader_sources",
                    "hbao.viewport.horizon_sources", "hbao.viewport.normal_sources",
                    "hbao.viewport.camera_sources", "hbao.viewport.view_swaps")
# Issue 8: a file past about 300 lines was doing several jobs.
MAX_MODULE_LINES = 300


def _module_name(path):
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path):
    """The package's modules that `path` imports, at any depth of its code."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package.split(".")
            base = base[:len(base) - node.level + 1]
            target = ".".join(base + ([node.module] if node.module else []))
            for alias in node.names:
                candidate = f"{target}.{alias.name}"
                found.add(candidate if _exists(candidate) else target)
    return found - {name}


def _exists(module):
    relative = module.split(".")[1:]
    return (PACKAGE.joinpath(*relative).with_suffix(".py").is_file()
            or PACKAGE.joinpath(*relative, "__init__.py").is_file())


def _graph():
    return {_module_name(path): _imports(path) for path in PACKAGE.rglob("*.py")}


def test_bpy_free_modules_import_without_blender():
    code = (f"import sys; sys.path.insert(0, {str(REPO / 'addon')!r})\n"
            f"import importlib\n"
            f"for name in {BPY_FREE_MODULES!r}: importlib.import_module(name)\n"
            f"assert 'bpy' not in sys.modules and 'gpu' not in sys.modules\n"
            f"print('IMPORTED')\n")
    completed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                               timeout=60)
    assert completed.returncode == 0 and "IMPORTED" in completed.stdout, completed.stderr


def test_the_import_graph_has_no_circle():
    graph = _graph()
    # A module imports its package's __init__ implicitly; only explicit edges count.
    state = {}

    def visit(module, path):
        state[module] = "open"
        for target in sorted(graph.get(module, ())):
            if state.get(target) == "open":
                raise AssertionError(f"import circle: {' -> '.join(path + [target])}")
            if target not in state:
                visit(target, path + [target])
        state[module] = "done"

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])


def test_the_node_does_not_know_the_hook():
    hook = {"hbao.helper_scene", "hbao.helper_lookup", "hbao.handlers", "hbao.engine",
            "hbao.helper_ao", "hbao.planning", "hbao.handover", "hbao.socket_values"}
    assert not _graph()["hbao.node"] & hook
    assert not _graph()["hbao.node_status"] & hook
    # The graph reader must see real edges, or the two tests above prove nothing.
    assert "hbao.node" in _graph()["hbao.helper_scene"]


def test_no_module_is_doing_several_jobs():
    sizes = {path.name: len(path.read_text().splitlines()) for path in PACKAGE.rglob("*.py")}
    too_long = {name: lines for name, lines in sizes.items() if lines > MAX_MODULE_LINES}
    assert not too_long
