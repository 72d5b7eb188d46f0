/* The splat kd-tree's wide tree (issue 29): the binary tree's levels
 * collapsed into nodes of up to CDL_SKD_WIDTH children whose bounding
 * spheres a photon ray's frustum tests in one SIMD step, with an explicit
 * stack instead of one recursive call per binary node. Collapsing only
 * skips sphere tests and culling nodes inside small subtrees; both merely
 * prune, and the leaf test decides each sample exactly, so a ray feeds
 * the same samples with the same weights. */
#include "spatial/splatkd.h"

#include "core/octahedral.h"
#include "spatial/splatkd_node.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A subtree of at most this many samples is tested without descending:
 * its 16-lane leaf tests run straight through, while each sphere test is
 * a branch the processor mispredicts often (Cornell box and WAVE rows of
 * Table 7.1 fastest from 96 to 192; 16, leaves alone, is 1.4x slower). */
#define RANGE_MAX 128u
#define PART_MARK (UINT32_MAX - 2) /* a part's root while the top is built */

typedef struct wbuild {
    cdl_skd *t;
    const uint32_t *part_of; /* per binary node: the part it is the root of, or UINT32_MAX */
    int fail;
} wbuild;

static int is_kind(cdl_skd_node nd, uint32_t kind) { return (nd.b & 3) == 3 && ((nd.b >> 2) & 3) == kind; }

static uint32_t size_of(const cdl_skd *t, uint32_t node)
{
    cdl_skd_range r = t->range[node];
    return r.hi > r.lo ? r.hi - r.lo : 0;
}

static cdl_skd_went entry_of(wbuild *w, uint32_t node, int top);

static uint32_t new_wide(wbuild *w)
{
    cdl_skd *t = w->t;
    if (t->nwide == t->capwide) {
        uint32_t cap = t->capwide ? 2 * t->capwide : 256;
        cdl_skd_wnode *nw = realloc(t->wide, sizeof *nw * cap);
        if (!nw) {
            w->fail = 1;
            return 0;
        }
        t->wide = nw;
        t->capwide = cap;
    }
    return t->nwide++;
}

static int expandable(const wbuild *w, uint32_t node, int top)
{
    cdl_skd_node nd = w->t->nodes[node];
    if ((nd.b & 3) == 3 || size_of(w->t, node) <= RANGE_MAX)
        return 0;
    return !(top && w->part_of[node] != UINT32_MAX);
}

/* The wide node over interior node `node`: its children the frontier of
 * its subtree grown by splitting the widest expandable sphere first, in
 * depth-first order. */
static uint32_t make_wide(wbuild *w, uint32_t node, int top)
{
    cdl_skd *t = w->t;
    uint32_t fr[CDL_SKD_WIDTH], nf = 0;
    uint32_t kids[2] = {node + 1, t->nodes[node].b >> 2};
    for (int k = 0; k < 2; k++)
        if (size_of(t, kids[k]))
            fr[nf++] = kids[k];
    for (;;) {
        int best = -1;
        for (uint32_t i = 0; i < nf; i++)
            if (expandable(w, fr[i], top) &&
                (best < 0 || t->lsph[4 * (size_t)fr[i] + 3] > t->lsph[4 * (size_t)fr[best] + 3]))
                best = (int)i;
        if (best < 0)
            break;
        uint32_t x = fr[best], l = x + 1, r = t->nodes[x].b >> 2;
        uint32_t add = (size_of(t, l) > 0) + (size_of(t, r) > 0);
        if (nf - 1 + add > CDL_SKD_WIDTH)
            break;
        uint32_t nx[CDL_SKD_WIDTH], j = 0;
        for (uint32_t i = 0; i < nf; i++) {
            if (i != (uint32_t)best) {
                nx[j++] = fr[i];
                continue;
            }
            if (size_of(t, l))
                nx[j++] = l;
            if (size_of(t, r))
                nx[j++] = r;
        }
        memcpy(fr, nx, sizeof(uint32_t) * j);
        nf = j;
    }
    cdl_skd_went e[CDL_SKD_WIDTH];
    for (uint32_t i = 0; i < nf && !w->fail; i++)
        e[i] = entry_of(w, fr[i], top);
    uint32_t id = new_wide(w);
    if (w->fail)
        return 0;
    cdl_skd_wnode *wn = &t->wide[id];
    for (uint32_t i = 0; i < CDL_SKD_WIDTH; i++) {
        const float *sp = t->lsph + 4 * (size_t)(i < nf ? fr[i] : 0);
        for (int a = 0; a < 3; a++)
            wn->c[a][i] = i < nf ? sp[a] : 0.0f;
        wn->c[3][i] = i < nf ? sp[3] : -INFINITY;
        wn->ref[i] = i < nf ? e[i].ref : 0;
        wn->n[i] = i < nf ? e[i].n : CDL_SKD_WEMPTY;
    }
    return id;
}

/* How the traversal continues at `node`, whose sphere has been tested. */
static cdl_skd_went entry_of(wbuild *w, uint32_t node, int top)
{
    cdl_skd *t = w->t;
    cdl_skd_node nd = t->nodes[node];
    cdl_skd_range rg = t->range[node];
    if (!size_of(t, node))
        return (cdl_skd_went){0, CDL_SKD_WEMPTY};
    if (top && w->part_of[node] != UINT32_MAX) /* a part's root: its part's entry, set in later */
        return (cdl_skd_went){w->part_of[node], PART_MARK};
    if (is_kind(nd, KIND_CULL) && size_of(t, node) > RANGE_MAX) {
        cdl_skd_went next = entry_of(w, node + 1, top);
        if (w->fail)
            return next;
        if (t->nwcull == t->capwcull) {
            uint32_t cap = t->capwcull ? 2 * t->capwcull : 64;
            cdl_skd_wcull *nc = realloc(t->wcull, sizeof *nc * cap);
            if (!nc) {
                w->fail = 1;
                return next;
            }
            t->wcull = nc;
            t->capwcull = cap;
        }
        float cmax = (float)(nd.b >> 16) / 65535.0f;
        cdl_vec3 n = cdl_oct_decode_raw(nd.a, 16);
        t->wcull[t->nwcull] = (cdl_skd_wcull){{n.x, n.y, n.z}, cmax * cmax * cdl_dot(n, n), next};
        return (cdl_skd_went){t->nwcull++, CDL_SKD_WCULL};
    }
    if ((nd.b & 3) == 3 || size_of(t, node) <= RANGE_MAX) /* a leaf, or a small subtree */
        return (cdl_skd_went){rg.lo, rg.hi - rg.lo};
    return (cdl_skd_went){make_wide(w, node, top), 0};
}

int cdl_skd_build_wide(cdl_skd *t)
{
    wbuild w = {t, NULL, 0};
    t->wpart = malloc(sizeof *t->wpart * (t->nparts ? t->nparts : 1));
    uint32_t *po = malloc(sizeof(uint32_t) * (t->nnodes ? t->nnodes : 1));
    if (!t->wpart || !po) {
        free(po);
        return -1;
    }
    for (uint32_t i = 0; i < t->nnodes; i++)
        po[i] = UINT32_MAX;
    w.part_of = po;
    t->wroot = (cdl_skd_went){0, CDL_SKD_WEMPTY};
    for (uint32_t p = 0; p < t->nparts && !w.fail; p++) {
        t->wpart[p] = entry_of(&w, t->parts[p].node, 0);
        po[t->parts[p].node] = p;
    }
    uint32_t nw0 = t->nwide, nc0 = t->nwcull;
    if (t->n && !w.fail) {
        /* the whole tree's top, down to the part roots */
        t->wroot = entry_of(&w, 0, 1);
        if (t->wroot.n == PART_MARK)
            t->wroot = t->wpart[t->wroot.ref];
        for (uint32_t i = nw0; i < t->nwide && !w.fail; i++)
            for (uint32_t k = 0; k < CDL_SKD_WIDTH; k++)
                if (t->wide[i].n[k] == PART_MARK) {
                    cdl_skd_went e = t->wpart[t->wide[i].ref[k]];
                    t->wide[i].ref[k] = e.ref;
                    t->wide[i].n[k] = e.n;
                }
        for (uint32_t i = nc0; i < t->nwcull && !w.fail; i++)
            if (t->wcull[i].next.n == PART_MARK)
                t->wcull[i].next = t->wpart[t->wcull[i].next.ref];
    }
    free(po);
    return w.fail ? -1 : 0;
}
