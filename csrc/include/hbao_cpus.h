/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Internal to the project's libraries, not installed: what "one thread per
 * core" counts, once for libhbao (hbao_params.threads = 0) and the EXR
 * reader (libhbao_exr, the tool): the CPUs this process may run on, its
 * affinity mask, which taskset, cgroup cpusets (containers) and farm
 * schedulers narrow, not every CPU the machine has online (a job given 8
 * of 64 cores would start 64 threads). A file that includes this defines
 * _GNU_SOURCE before its first include (sched_getaffinity, CPU_COUNT). */
#ifndef HBAO_CPUS_H
#define HBAO_CPUS_H

#include <limits.h>
#include <unistd.h>
#ifdef __linux__
#include <sched.h>
#endif

/* At least 1. Falls back to the CPUs online where the mask cannot be read
 * (not Linux, or more CPUs than a cpu_set_t holds). */
static inline int hbao_usable_cpus(void) {
#if defined(__linux__) && defined(CPU_COUNT)
    cpu_set_t allowed;
    if (sched_getaffinity(0, sizeof allowed, &allowed) == 0) {
        const int count = CPU_COUNT(&allowed);
        if (count > 0) return count;
    }
#endif
    const long online = sysconf(_SC_NPROCESSORS_ONLN);
    return online < 1 ? 1 : online > INT_MAX ? INT_MAX : (int)online;
}

#endif
