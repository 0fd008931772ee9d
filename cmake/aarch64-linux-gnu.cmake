# SPDX-License-Identifier: GPL-2.0-or-later
# A cross build for 64-bit ARM Linux with Debian's cross compiler
# (gcc-aarch64-linux-gnu), whose programs run under qemu-user: ctest starts
# each test through CMAKE_CROSSCOMPILING_EMULATOR. scripts/test_arm64.sh uses
# it to hold the generic horizon kernel (Advanced SIMD there) to the scalar
# reference on an ARM64 CPU.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64 -L /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
