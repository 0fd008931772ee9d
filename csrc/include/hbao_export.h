/* SPDX-License-Identifier: GPL-2.0-or-later */
/* The one export macro: the shared library exports the public API and
 * nothing else (everything else is built with hidden visibility). */
#ifndef HBAO_EXPORT_H
#define HBAO_EXPORT_H

#if defined(_WIN32)
#if defined(HBAO_BUILDING_LIBRARY)
#define HBAO_EXPORT __declspec(dllexport)
#else
#define HBAO_EXPORT __declspec(dllimport)
#endif
#else
#define HBAO_EXPORT __attribute__((visibility("default")))
#endif

#endif /* HBAO_EXPORT_H */
