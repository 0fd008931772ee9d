/* SPDX-License-Identifier: GPL-2.0-or-later */
#include "fuzz_input_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static char folder[4096];
static char input_path[4096 + 16];

/* Every name a target writes in the folder (see fuzz_scratch_folder()). */
static const char *const scratch_names[] = {"input.exr", "out.exr", "out.png"};

static void remove_scratch_folder(void) {
    char path[4096 + 16];
    for (size_t i = 0; i < sizeof scratch_names / sizeof scratch_names[0]; ++i) {
        snprintf(path, sizeof path, "%s/%s", folder, scratch_names[i]);
        unlink(path);
    }
    rmdir(folder);
}

const char *fuzz_scratch_folder(void) {
    if (folder[0] != '\0') return folder;
    const char *base = getenv("TMPDIR");
    snprintf(folder, sizeof folder, "%s/hbao-fuzz-XXXXXX", base && base[0] ? base : "/tmp");
    if (mkdtemp(folder) == NULL) {
        perror("fuzz: mkdtemp");
        abort();
    }
    atexit(remove_scratch_folder);
    return folder;
}

const char *fuzz_input_file(const uint8_t *data, size_t size) {
    if (input_path[0] == '\0')
        snprintf(input_path, sizeof input_path, "%s/input.exr", fuzz_scratch_folder());
    FILE *file = fopen(input_path, "wb");
    if (file == NULL || (size > 0 && fwrite(data, 1, size, file) != size) || fclose(file) != 0) {
        perror("fuzz: writing the input file");
        abort();
    }
    return input_path;
}
