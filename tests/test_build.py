# SPDX-License-Identifier: GPL-2.0-or-later
"""The build's choice of compiler for the SIMD horizon kernels
(cmake/hbao_kernels.cmake): clang where a GCC build finds one and clang
takes the build's flags, GCC otherwise; each way the kernels give the scalar
reference's results to the bit. Plain pytest: CMake and the compilers that
scripts/setup.sh installs, no Blender."""
import os
import shutil
import subprocess

import pytest

from conftest import BUILD, REPO

LIBRARY = BUILD / "libhbao.so"


def comment_section(path):
    """The compilers named in an ELF file's .comment section."""
    shown = subprocess.run(["readelf", "-p", ".comment", str(path)], stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True, check=True)
    return shown.stdout


def configure(build, *options, env=None):
    configured = subprocess.run(
        ["cmake", "-S", str(REPO), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
         "-DHBAO_BUILD_TOOL=OFF", "-DHBAO_BUILD_BENCHMARKS=OFF", *options],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    assert configured.returncode == 0, configured.stdout
    return configured.stdout


def build_target(build, target):
    built = subprocess.run(["cmake", "--build", str(build), "-j2", "--target", target],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert built.returncode == 0, built.stdout
    return built.stdout


def test_the_library_holds_clang_kernels_where_clang_is_installed():
    """The suite's own build (GCC, clang installed by scripts/setup.sh)
    links clang's kernel objects into libhbao.so beside GCC's."""
    if not LIBRARY.exists():
        pytest.fail(f"{LIBRARY} missing: build with scripts/test.sh or cmake first")
    assert shutil.which("clang"), "clang missing: scripts/setup.sh installs it"
    compilers = comment_section(LIBRARY)
    assert "GCC:" in compilers and "clang version" in compilers, compilers


def test_gcc_keeps_the_kernels_where_clang_refuses_the_flags(tmp_path):
    """A GCC-only flag in CFLAGS (-Wlogical-op; with -Werror clang refuses
    it) leaves the kernels to GCC, with a message, instead of a failed
    build; those kernels match the scalar reference to the bit."""
    build = tmp_path / "build"
    said = configure(build, "-DHBAO_BUILD_TESTS=ON", "-DCMAKE_C_FLAGS=-Wlogical-op")
    assert "refuses this build's flags" in said and "-Wlogical-op" in said, said
    built = build_target(build, "test_ao")
    assert "horizon kernel with" not in built
    assert not (build / "kernels" / "horizon_avx512.o").exists()
    for part in range(1, 5):
        run = subprocess.run([str(build / "csrc" / "tests" / "test_ao"),
                              f"simd_paths_match_scalar_reference_part_{part}_of_4"],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        assert run.returncode == 0 and "PASS" in run.stdout, run.stdout


def test_clang_kernels_keep_the_hardening_gcc_turns_on_by_itself(tmp_path):
    """A GCC that turns CET on by itself (Ubuntu's; here a wrapper that adds
    -fcf-protection=full): clang's kernel objects carry the same IBT and
    SHSTK marking as GCC's, or linking them would drop the library's."""
    wrapper = tmp_path / "gcc-with-cet"
    wrapper.write_text(f'#!/bin/sh\nexec {shutil.which("gcc")} -fcf-protection=full "$@"\n')
    wrapper.chmod(0o755)
    build = tmp_path / "build"
    configure(build, "-DHBAO_BUILD_TESTS=OFF", env=dict(os.environ, CC=str(wrapper)))
    build_target(build, "hbao_kernels")
    for kernel in ("avx2", "avx512"):
        notes = subprocess.run(["readelf", "-n", str(build / "kernels" / f"horizon_{kernel}.o")],
                               stdout=subprocess.PIPE, text=True, check=True).stdout
        assert "IBT, SHSTK" in notes, notes
        assert "clang version" in comment_section(build / "kernels" / f"horizon_{kernel}.o")
