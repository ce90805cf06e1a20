/* class_view.c — the screen classification's view of the pack (issue
 * 29): the materials of the cells in view numbered densely, each
 * combination's set in those numbers, and the short list of candidates
 * in cost order that no earlier one dominates, so the cover search
 * follows the view and not the world.  CPU only; screen.c uploads it. */
#include "rt_internal.h"

#include <stdlib.h>
#include <string.h>

void rt_class_view_free(rt_class_view *v)
{
    free(v->cand);
    free(v->rec);
    free(v->remap);
    memset(v, 0, sizeof *v);
}

/* Whether combination a fits wherever b does: a base combination fits
 * everywhere, a class inside its interval (the uploaded, rounded one). */
static bool fits_where(const rt_pack *p, const float *dist, uint32_t a, uint32_t b)
{
    if ((int)a < p->nbase)
        return true;
    return (int)b >= p->nbase && dist[2 * a] <= dist[2 * b] && dist[2 * a + 1] >= dist[2 * b + 1];
}

bool rt_class_view_build(const rt_pack *p, const uint32_t *order, const float *dist,
                         const uint32_t *vmask, int full_words, bool no_classes,
                         rt_class_view *v)
{
    int n = p->ncombos;
    if (!v->cand) {
        v->cand = malloc((size_t)(n > 0 ? n : 1) * sizeof *v->cand);
        v->rec = malloc((size_t)(n > 0 ? n : 1) * (size_t)(1 + full_words) * sizeof *v->rec);
        v->remap = malloc((size_t)(p->nmaterials > 0 ? p->nmaterials : 1) * sizeof *v->remap);
        if (!v->cand || !v->rec || !v->remap) {
            rt_class_view_free(v);
            return false;
        }
    }
    v->nview = 0;
    for (int m = 0; m < p->nmaterials; m++)
        v->remap[m] = (vmask[m / 32] >> (m % 32)) & 1u ? v->nview++ : -1;
    v->words = v->nview <= 32 ? 1 : full_words;
    int W = v->words, R = 1 + W;
    memset(v->rec, 0, (size_t)n * (size_t)R * sizeof *v->rec);
    for (int i = 0; i < n; i++) {
        uint32_t *r = v->rec + (size_t)i * (size_t)R;
        for (int k = 0; k < p->combos[i].nmaterials; k++) {
            int m = p->combos[i].materials[k];
            int b = m >= 0 && m < p->nmaterials ? v->remap[m] : -1;
            if (b < 0)
                r[0] |= RT_CLASS_OUTSIDE;
            else
                r[1 + b / 32] |= 1u << (b % 32);
        }
    }
    /* the candidates: in cost order, those no earlier candidate dominates
     * (covers its materials in view, and fits wherever it does).  A tile
     * none of whose cells is outside needs a material unless some
     * combination has none, so without such a one a combination with no
     * material in view covers no tile's set: not a candidate. */
    bool empty_need = false;
    for (int i = 0; i < n; i++)
        empty_need |= p->combos[i].nmaterials == 0;
    v->ncand = 0;
    for (int k = 0; k < n; k++) {
        uint32_t c = order[k];
        if (no_classes && (int)c >= p->nbase)
            continue;
        const uint32_t *mc = v->rec + (size_t)c * (size_t)R + 1;
        bool dominated = !empty_need;
        for (int w = 0; w < W && dominated; w++)
            dominated = mc[w] == 0;
        for (int j = 0; j < v->ncand && !dominated; j++) {
            uint32_t d = v->cand[j];
            if (!fits_where(p, dist, d, c))
                continue;
            const uint32_t *md = v->rec + (size_t)d * (size_t)R + 1;
            bool covers = true;
            for (int w = 0; w < W && covers; w++)
                covers = (mc[w] & ~md[w]) == 0;
            dominated = covers;
        }
        if (!dominated)
            v->cand[v->ncand++] = c;
    }
    return true;
}
