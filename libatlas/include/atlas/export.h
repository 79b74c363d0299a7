/* atlas/export.h - which declarations a shared libatlas exports.
 *
 * ATLAS_API marks a function of the C API (atlas/atlas.h). The C API is
 * compiled with hidden visibility, so only what carries ATLAS_API is visible;
 * the shared library's version script (libatlas/atlas.map) also exports the
 * C++ API (namespace atlas) and hides everything else. With the static
 * libraries the macro changes nothing.
 *
 * Header-only.
 */
#ifndef ATLAS_EXPORT_H
#define ATLAS_EXPORT_H

#if defined(_WIN32)
#  if defined(ATLAS_BUILDING_SHARED)
#    define ATLAS_API __declspec(dllexport)
#  elif defined(ATLAS_USING_SHARED)
#    define ATLAS_API __declspec(dllimport)
#  else
#    define ATLAS_API
#  endif
#elif defined(__GNUC__) || defined(__clang__)
#  define ATLAS_API __attribute__((visibility("default")))
#else
#  define ATLAS_API
#endif

#endif /* ATLAS_EXPORT_H */
