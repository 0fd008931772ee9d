# SPDX-License-Identifier: GPL-2.0-or-later
# The SIMD horizon kernels (csrc/lib/horizon_avx2.c, horizon_avx512.c): compiled
# for their instruction sets and chosen at run time (horizon.c), so the library
# still runs on any x86-64; and, where the library's compiler is GCC, compiled
# by clang (HBAO_CLANG_KERNELS; HBAO_CLANG names the clang): the same
# operations to the bit (the tests hold every kernel to the scalar reference),
# in less time. scripts/bench_ab_pairs.sh, 1080p, Zen 5, clang 14 against GCC
# 12 (docs/speed.md, session 42): AVX-512 0.957 on 2 threads, 0.946 half, 0.942
# for 8 x 6 + blur 15; AVX2 0.889, 0.915, 0.871. The rest of the library stays
# with GCC (the whole of it by clang took 1.73 times as long at half
# resolution, session 41).
#
# Included by CMakeLists.txt with HBAO_LIBRARY_SOURCES (the library's sources)
# and HBAO_LIBRARY_OPTIONS (its compile options) set; removes the kernels that
# clang compiles from HBAO_LIBRARY_SOURCES and puts their objects in the static
# library hbao_kernels, which hbao_objects and libhbao.so link. Sets
# HBAO_KERNELS_BUILT_BY (bench_speed says it).
#
# clang is left out, and GCC compiles the kernels, where one compiler's
# runtime must serve all (the sanitizer and fuzzer builds), where a build
# type's flags cannot be known (a multi-configuration generator), in a cross
# build, and where clang refuses this build's flags (GCC's CFLAGS, such as
# -Wlogical-op or -mtls-dialect=gnu2: tried once at configure time).

set(HBAO_KERNELS_BUILT_BY "${CMAKE_C_COMPILER_ID} ${CMAKE_C_COMPILER_VERSION}")
if(NOT CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
  return()
endif()
set(kernels avx2 -mavx2 avx512 -mavx512f)

# The hardening a distribution's GCC turns on by itself (Ubuntu's: CET, the
# stack protector, stack clash protection, _FORTIFY_SOURCE), as clang flags:
# clang's objects must not drop what GCC's carry (a CET-marked library loses
# its marking if one object lacks it).
function(hbao_gcc_own_defaults type_flags out)
  execute_process(COMMAND ${CMAKE_C_COMPILER} ${type_flags} -dM -E -x c /dev/null
                  OUTPUT_VARIABLE macros ERROR_QUIET)
  execute_process(COMMAND ${CMAKE_C_COMPILER} ${type_flags} -Q --help=common
                  OUTPUT_VARIABLE help ERROR_QUIET)
  set(flags "")
  set(cet_1 branch)
  set(cet_2 return)
  set(cet_3 full)
  if(macros MATCHES "#define __CET__ ([123])")
    list(APPEND flags -fcf-protection=${cet_${CMAKE_MATCH_1}})
  endif()
  foreach(level ALL STRONG EXPLICIT "")
    string(TOLOWER "${level}" option)
    if(level STREQUAL "" AND macros MATCHES "#define __SSP__ ")
      list(APPEND flags -fstack-protector)
      break()
    elseif(NOT level STREQUAL "" AND macros MATCHES "#define __SSP_${level}__ ")
      list(APPEND flags -fstack-protector-${option})
      break()
    endif()
  endforeach()
  if(help MATCHES "[ \t]-fstack-clash-protection[ \t]+\\[enabled\\]")
    list(APPEND flags -fstack-clash-protection)
  endif()
  if(macros MATCHES "#define _FORTIFY_SOURCE ([0-9]+)")
    list(APPEND flags -D_FORTIFY_SOURCE=${CMAKE_MATCH_1})
  endif()
  set(${out} ${flags} PARENT_SCOPE)
endfunction()

set(kernel_compiler "")
get_property(multi_config GLOBAL PROPERTY GENERATOR_IS_MULTI_CONFIG)
if(HBAO_CLANG_KERNELS AND CMAKE_C_COMPILER_ID STREQUAL "GNU" AND NOT HBAO_SANITIZE
   AND NOT HBAO_BUILD_FUZZERS AND NOT multi_config AND NOT CMAKE_CROSSCOMPILING)
  find_program(HBAO_CLANG clang DOC "The clang that compiles the SIMD horizon kernels")
  string(TOUPPER "${CMAKE_BUILD_TYPE}" build_type)
  # -fno-lto: with GCC's -flto in the flags, clang would write LLVM bitcode
  separate_arguments(type_flags UNIX_COMMAND "${CMAKE_C_FLAGS} ${CMAKE_C_FLAGS_${build_type}}")
  hbao_gcc_own_defaults("${type_flags}" gcc_defaults)
  list(APPEND type_flags ${gcc_defaults} -fno-lto)
  # what hbao_objects' target properties add (C11, position-independent,
  # hidden symbols)
  set(common_flags ${type_flags} -std=c11 -fPIC -fvisibility=hidden)
  if(HBAO_CLANG)
    set(probe ${PROJECT_BINARY_DIR}/kernels/probe.c)
    file(WRITE ${probe} "#include <immintrin.h>\nint hbao_probe(void);\nint hbao_probe(void) { return 0; }\n")
    execute_process(COMMAND ${HBAO_CLANG} ${common_flags} ${HBAO_LIBRARY_OPTIONS} -mavx512f
                            -c ${probe} -o ${probe}.o
                    RESULT_VARIABLE probe_result ERROR_VARIABLE probe_error OUTPUT_QUIET)
    if(probe_result EQUAL 0)
      set(kernel_compiler ${HBAO_CLANG})
      execute_process(COMMAND ${HBAO_CLANG} -dumpversion OUTPUT_VARIABLE clang_version
                      OUTPUT_STRIP_TRAILING_WHITESPACE)
      set(HBAO_KERNELS_BUILT_BY "clang ${clang_version}")
    else()
      string(STRIP "${probe_error}" probe_error)
      if(probe_error STREQUAL "")
        set(probe_error "${probe_result}")
      endif()
      message(STATUS "${HBAO_CLANG} refuses this build's flags (${probe_error}): "
                     "the SIMD horizon kernels are compiled by ${CMAKE_C_COMPILER}")
    endif()
  else()
    message(STATUS "No clang found: the SIMD horizon kernels are compiled by ${CMAKE_C_COMPILER}")
  endif()
endif()

set(kernel_objects "")
while(kernels)
  list(POP_FRONT kernels kernel kernel_flag)
  set(source ${PROJECT_SOURCE_DIR}/csrc/lib/horizon_${kernel}.c)
  if(NOT kernel_compiler)
    set_source_files_properties(${source} PROPERTIES COMPILE_OPTIONS ${kernel_flag})
    continue()
  endif()
  list(REMOVE_ITEM HBAO_LIBRARY_SOURCES ${source})
  set(object ${PROJECT_BINARY_DIR}/kernels/horizon_${kernel}.o)
  # hbao_objects' definitions, include directories and options (a parent
  # project's too)
  add_custom_command(OUTPUT ${object}
    BYPRODUCTS ${object}.d
    COMMAND ${CMAKE_C_COMPILER_LAUNCHER} ${kernel_compiler} ${common_flags}
      "-D$<JOIN:$<TARGET_PROPERTY:hbao_objects,COMPILE_DEFINITIONS>,;-D>"
      "-I$<JOIN:$<TARGET_PROPERTY:hbao_objects,INCLUDE_DIRECTORIES>,;-I>"
      "$<TARGET_PROPERTY:hbao_objects,COMPILE_OPTIONS>" ${kernel_flag} -MD -MF ${object}.d -c ${source} -o ${object}
    DEPENDS ${source}
    DEPFILE ${object}.d
    COMMENT "Building the ${kernel} horizon kernel with ${kernel_compiler}"
    COMMAND_EXPAND_LISTS VERBATIM)
  list(APPEND kernel_objects ${object})
endwhile()
if(kernel_objects)
  add_library(hbao_kernels STATIC ${kernel_objects})
  set_target_properties(hbao_kernels PROPERTIES LINKER_LANGUAGE C)
endif()
