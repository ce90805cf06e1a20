/* scene.h — the compiler's scene-to-pack API, one header per component:
 *   terrain.h     heightfield and terrain inputs (terrain.c, raster.c)
 *   scene_load.h  a loaded scene, its painted masks, import search
 *                 (scene.c, painted.c, search.c)
 *   analysis.h    the combinations a scene has (analysis.c, precision.c)
 *   compose.h     composite shaders (compose.c)
 *   cache.h       the SPIR-V cache (cache.c)
 * and here `splatc build`, the shader pack (build.c; PACK.md).
 */
#ifndef SPLAT_SCENE_H
#define SPLAT_SCENE_H

#include <stdio.h>

#include "cache.h"
#include "compose.h"
#include "far_atlas.h"
#include "splatc.h"

/* `splatc build` (build.c): splat_build and its desc are in splatc.h. */

#endif
