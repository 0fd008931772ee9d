/* SPDX-License-Identifier: GPL-2.0-or-later */
/* Version, result messages, implementation names and defaults: the small
 * parts of the public API. */
#include "internal_hbao.h"

int32_t hbao_version(void) {
    return HBAO_VERSION;
}

const char *hbao_result_message(hbao_result result) {
    static const char *const messages[] = {
#define HBAO_RESULT_MESSAGE_ENTRY(name, message) message,
        HBAO_RESULT_LIST(HBAO_RESULT_MESSAGE_ENTRY)
#undef HBAO_RESULT_MESSAGE_ENTRY
    };
    if (result < 0 || result >= HBAO_RESULT_COUNT) return "unknown result code";
    return messages[result];
}

const char *hbao_note_message(uint32_t note) {
    if (note == HBAO_NOTE_REFERENCE_SEARCH)
        return "not enough memory for the fast search's copy of the depths; the reference "
               "search computed the AO (the same result, several times slower)";
    if (note == HBAO_NOTE_RADIUS_BEYOND_IMAGE)
        return "at most of the image's pixels the radius spans more pixels than the image's "
               "shorter side, so most samples fall outside the image and the AO comes out too "
               "light: lower the radius, or render more pixels";
    if (note == HBAO_NOTE_RADIUS_UNDER_A_PIXEL)
        return "at most of the image's pixels the radius spans less than a pixel, so nothing "
               "is sampled there and the AO is 1 (no occlusion): raise the radius (it is in "
               "the scene's units), or render more pixels";
    return "unknown note";
}

const char *hbao_implementation_name(int32_t implementation) {
    static const char *const names[] = {"auto", "scalar", "AVX2", "AVX-512", "generic"};
    _Static_assert(sizeof names / sizeof names[0] == HBAO_IMPLEMENTATION_COUNT, "a name each");
    if (implementation < 0 || implementation >= HBAO_IMPLEMENTATION_COUNT)
        return "unknown implementation";
    return names[implementation];
}

void hbao_params_default(hbao_params *params) {
    if (params == NULL) return;
    const hbao_params defaults = HBAO_PARAMS_DEFAULT_INITIALIZER;
    *params = defaults;
}

void hbao_camera_default(hbao_camera *camera) {
    if (camera == NULL) return;
    const hbao_camera defaults = HBAO_CAMERA_DEFAULT_INITIALIZER;
    *camera = defaults;
}

size_t hbao_params_size(void) {
    return sizeof(hbao_params);
}

size_t hbao_camera_size(void) {
    return sizeof(hbao_camera);
}

size_t hbao_view_size(void) {
    return sizeof(hbao_view);
}
