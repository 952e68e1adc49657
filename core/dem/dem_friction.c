/* dem_friction.c — 2D inter-particle friction (Meier 2009 ch. 7, Table 7.1):
 * return map, forces and couples, history; contract: dem_friction.h. */
#include "dem_friction.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/base/grow.h"

int pk_fric_law_active(const pk_fric_law *law) { return law && (law->tan_rho > 0 || law->h > 0); }

int pk_fric_return_map(const pk_fric_law *law, double fn, double gamma, double gamma_pl_n,
                       double alpha_n, pk_fric_point *out)
{
    const double Et = law->E_t, h = law->h, c = fn * law->tan_rho; /* (7.11) */
    double ftr = Et * (gamma - gamma_pl_n);                        /* elastic predictor */
    double Y = fabs(ftr) - h * alpha_n;
    out->gamma_pl = gamma_pl_n;
    out->alpha = alpha_n;
    out->ft = ftr;
    out->dlambda = 0;
    if (Y < c) /* stick; Table 7.1 slips on Y >= c */
        return 0;
    double sg = ftr >= 0 ? 1 : -1;  /* sgn(0) := +1 */
    double dl = (Y - c) / (Et + h); /* (7.16) */
    out->dlambda = dl;
    out->gamma_pl = gamma_pl_n + dl * sg; /* (7.17), erratum of (7.12) */
    out->alpha = alpha_n + dl;
    /* |f_t| = |f_tr| − E_t Δλ in the form that cannot flip sign and
     * is exactly 0 for c = h = 0 */
    out->ft = sg * (h * fabs(ftr) + Et * h * alpha_n + Et * c) / (Et + h);
    return 1;
}

void pk_fric_hist_free(pk_fric_hist *h)
{
    free(h->key);
    free(h->gamma);
    free(h->gamma_pl);
    free(h->alpha);
    memset(h, 0, sizeof *h);
}

static int hist_reserve(pk_fric_hist *h, size_t n)
{
    if (n <= h->cap && h->key)
        return 0;
    size_t cap = n ? n : 1;
    const pk_grow_item arrays[] = {PK_GROW_ITEM(h->key, 1), PK_GROW_ITEM(h->gamma, 1),
                                   PK_GROW_ITEM(h->gamma_pl, 1), PK_GROW_ITEM(h->alpha, 1)};
    if (pk_grow(arrays, 4, cap) != 0)
        return -1;
    h->cap = cap;
    return 0;
}

int pk_fric_hist_copy(pk_fric_hist *dst, const pk_fric_hist *src)
{
    if (hist_reserve(dst, src->n) != 0)
        return -1;
    dst->n = src->n;
    if (src->n) {
        memcpy(dst->key, src->key, src->n * sizeof *src->key);
        memcpy(dst->gamma, src->gamma, src->n * sizeof *src->gamma);
        memcpy(dst->gamma_pl, src->gamma_pl, src->n * sizeof *src->gamma_pl);
        memcpy(dst->alpha, src->alpha, src->n * sizeof *src->alpha);
    }
    return 0;
}

long pk_fric_hist_find(const pk_fric_hist *h, uint64_t key)
{
    size_t lo = 0, hi = h ? h->n : 0;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (h->key[mid] < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return h && lo < h->n && h->key[lo] == key ? (long)lo : -1;
}

void pk_fric_pairs_free(pk_fric_pairs *w)
{
    double **arr[] = {&w->gamma, &w->gamma_pl, &w->alpha, &w->ft, &w->dlambda, &w->keff, &w->ct};
    for (size_t k = 0; k < sizeof arr / sizeof *arr; k++)
        free(*arr[k]);
    memset(w, 0, sizeof *w);
}

static int pairs_reserve(pk_fric_pairs *w, size_t n)
{
    if (n <= w->cap && w->gamma)
        return 0;
    size_t cap = n ? n : 1;
    const pk_grow_item arrays[] = {PK_GROW_ITEM(w->gamma, 1),   PK_GROW_ITEM(w->gamma_pl, 1),
                                   PK_GROW_ITEM(w->alpha, 1),   PK_GROW_ITEM(w->ft, 1),
                                   PK_GROW_ITEM(w->dlambda, 1), PK_GROW_ITEM(w->keff, 1),
                                   PK_GROW_ITEM(w->ct, 1)};
    if (pk_grow(arrays, sizeof arrays / sizeof *arrays, cap) != 0)
        return -1;
    w->cap = cap;
    return 0;
}

static inline uint64_t pair_key(size_t i, size_t j)
{
    return (uint64_t)(uint32_t)i << 32 | (uint32_t)j;
}

int pk_dem_fric_eval(const pk_dem_pairs *c, pk_fric_ctx *fc, const double *x, const double *u,
                     const double *r, size_t np, double E_n, double *f, double *gu, double S[9],
                     pk_fric_totals *tot)
{
    (void)x;
    const pk_fric_law *law = fc->law;
    pk_fric_pairs *w = &fc->w;
    if (pairs_reserve(w, c->n) != 0)
        return -1;
    if (gu)
        memset(gu, 0, np * sizeof *gu);
    pk_fric_totals t = {0};
    for (size_t p = 0; p < c->n; p++) {
        size_t i = (size_t)c->i[p], j = (size_t)c->j[p];
        long hk = pk_fric_hist_find(fc->hist_n, pair_key(i, j));
        double g_n = hk >= 0 ? fc->hist_n->gamma[hk] : 0;
        double gpl_n = hk >= 0 ? fc->hist_n->gamma_pl[hk] : 0;
        double al_n = hk >= 0 ? fc->hist_n->alpha[hk] : 0;
        w->ft[p] = w->dlambda[p] = w->keff[p] = w->ct[p] = 0;
        w->gamma[p] = 0;
        w->gamma_pl[p] = 0;
        w->alpha[p] = al_n; /* broken: γ = γ_pl = 0, α kept (Table 7.1, 3.) */
        double len = c->len[p], eps = c->eps[p];
        if (!(eps >= 0) || !(len > 0))
            continue;
        const double *l = &c->l[3 * p];
        double nx = l[0] / len, ny = l[1] / len;
        double tx = -ny, ty = nx; /* t = Ω n (7.3) */
        double ln[3];
        pk_dem_branch(&fc->g_n, &fc->x_n[3 * i], &fc->x_n[3 * j], ln);
        double lnl = sqrt(ln[0] * ln[0] + ln[1] * ln[1]);
        double tnx = lnl > 0 ? -ln[1] / lnl : tx, tny = lnl > 0 ? ln[0] / lnl : ty;
        double du = (u[i] - fc->u_n[i]) + (u[j] - fc->u_n[j]);
        /* (7.5): rotation part + translation part −|lⁿ| tⁿ·nⁿ⁺¹ */
        double gamma = g_n + du * len / (r[i] + r[j]) - lnl * (tnx * nx + tny * ny);
        double fn = pk_dem_pair_E(c, p, E_n) * eps;
        pk_fric_point pt;
        int slip = pk_fric_return_map(law, fn, gamma, gpl_n, al_n, &pt);
        double ct = (lnl / len) * (tnx * tx + tny * ty); /* (7.20) */
        w->gamma[p] = gamma;
        w->gamma_pl[p] = pt.gamma_pl;
        w->alpha[p] = pt.alpha;
        w->ft[p] = pt.ft;
        w->dlambda[p] = pt.dlambda;
        w->ct[p] = ct;
        w->keff[p] = slip ? law->E_t * law->h / (law->E_t + law->h) : law->E_t;
        t.sliding += (size_t)slip;
        t.energy += 0.5 * (pt.ft * pt.ft / law->E_t + law->h * pt.alpha * pt.alpha); /* (7.6) */
        t.dissipation += pt.dlambda * fn * law->tan_rho;                             /* (7.13) */
        /* f_i = −f_t ∂γ/∂x_i with ∂γ/∂x_i = c_t t − (Δu/R) n: (7.19) plus the
         * central term of the rotation part of (7.5); m_i/r_i = −f_t s, s = |l|/R
         * (7.21 with its s).  The exact gradient of Ŵ_t (7.18): see the header. */
        double R = r[i] + r[j], sc = len / R, cn = pt.ft * du / R;
        double fx = -pt.ft * ct * tx + cn * nx, fy = -pt.ft * ct * ty + cn * ny; /* on i */
        if (f) {
            f[3 * i] += fx, f[3 * i + 1] += fy;
            f[3 * j] -= fx, f[3 * j + 1] -= fy;
        }
        if (gu) {
            gu[i] -= sc * pt.ft;
            gu[j] -= sc * pt.ft;
        }
        if (S) {
            S[0] += fx * l[0], S[1] += fx * l[1];
            S[3] += fy * l[0], S[4] += fy * l[1];
        }
    }
    if (tot)
        *tot = t;
    return 0;
}

double pk_dem_fric_gershgorin(const pk_dem_pairs *c, const pk_fric_ctx *fc, size_t np)
{
    double *row = calloc(np ? np : 1, sizeof *row);
    if (!row)
        return INFINITY;
    for (size_t p = 0; p < c->n && p < fc->w.cap; p++) {
        if (!(c->eps[p] >= 0) || !(c->len[p] > 0))
            continue;
        /* the (x_i, x_j, u_i, u_j) block is k c_t² [t; t; 1; 1]-outer-like; every
         * row sum is <= k c̃²(2√2 + 2) <= 5 k c̃², c̃ = max(1, |c_t|); plus the
         * geometric term |f_t|/|l| of the turning direction (×4 entries) */
        double ct = fmax(1, fabs(fc->w.ct[p]));
        double s = 5 * fc->w.keff[p] * ct * ct + 4 * fabs(fc->w.ft[p]) / c->len[p];
        row[c->i[p]] += s;
        row[c->j[p]] += s;
    }
    double m = 0;
    for (size_t k = 0; k < np; k++)
        m = fmax(m, row[k]);
    free(row);
    return m;
}

typedef struct {
    uint64_t key;
    double g, gpl, al;
} hist_row;

static int cmp_row(const void *a, const void *b)
{
    uint64_t x = ((const hist_row *)a)->key, y = ((const hist_row *)b)->key;
    return x < y ? -1 : x > y;
}

int pk_fric_hist_collect(const pk_dem_pairs *c, const pk_fric_ctx *fc, pk_fric_hist *out)
{
    size_t nold = fc->hist_n ? fc->hist_n->n : 0;
    hist_row *rows = malloc((c->n + nold + 1) * sizeof *rows);
    if (!rows)
        return -1;
    size_t n = 0;
    for (size_t p = 0; p < c->n; p++) {
        int contact = c->eps[p] >= 0 && c->len[p] > 0;
        if (contact || fc->w.alpha[p] > 0)
            rows[n++] = (hist_row){pair_key((size_t)c->i[p], (size_t)c->j[p]), fc->w.gamma[p],
                                   fc->w.gamma_pl[p], fc->w.alpha[p]};
    }
    qsort(rows, n, sizeof *rows, cmp_row);
    /* committed pairs with α > 0 that left the candidate list keep α */
    size_t ncand = n;
    for (size_t k = 0; k < nold; k++) {
        if (!(fc->hist_n->alpha[k] > 0))
            continue;
        hist_row key = {.key = fc->hist_n->key[k]};
        if (!bsearch(&key, rows, ncand, sizeof *rows, cmp_row))
            rows[n++] = (hist_row){fc->hist_n->key[k], 0, 0, fc->hist_n->alpha[k]};
    }
    qsort(rows, n, sizeof *rows, cmp_row);
    int rc = hist_reserve(out, n);
    if (rc == 0) {
        out->n = n;
        for (size_t k = 0; k < n; k++) {
            out->key[k] = rows[k].key;
            out->gamma[k] = rows[k].g;
            out->gamma_pl[k] = rows[k].gpl;
            out->alpha[k] = rows[k].al;
        }
    }
    free(rows);
    return rc;
}
