/* A DAQP workspace kept across solves (its working set is the warm start of the next solve),
 * behind a handle so that Rust needs no DAQP struct layouts. Problem data are copied in; the
 * layout is DAQP's: H row-major n x n, A row-major (m - ms) x n, bounds [simple; general]. */
#include "api.h"
#include <stdlib.h>
#include <string.h>

typedef struct {
    DAQPWorkspace work;
    DAQPProblem qp;
    DAQPResult res;
    int ready;
} peer_daqp;

peer_daqp *peer_daqp_new(int n, int m, int ms) {
    peer_daqp *p = calloc(1, sizeof(peer_daqp));
    if (!p) return NULL;
    p->qp.n = n;
    p->qp.m = m;
    p->qp.ms = ms;
    p->qp.H = calloc((size_t)n * n, sizeof(c_float));
    p->qp.f = calloc(n, sizeof(c_float));
    p->qp.A = calloc((size_t)(m - ms) * n + 1, sizeof(c_float));
    p->qp.bupper = calloc(m, sizeof(c_float));
    p->qp.blower = calloc(m, sizeof(c_float));
    p->qp.sense = calloc(m, sizeof(int));
    p->res.x = calloc(n, sizeof(c_float));
    p->res.lam = calloc(m, sizeof(c_float));
    p->work.settings = NULL;
    if (!p->qp.H || !p->qp.f || !p->qp.A || !p->qp.bupper || !p->qp.blower || !p->qp.sense ||
        !p->res.x || !p->res.lam) {
        free(p->qp.H); free(p->qp.f); free(p->qp.A); free(p->qp.bupper); free(p->qp.blower);
        free(p->qp.sense); free(p->res.x); free(p->res.lam);
        free(p);
        return NULL;
    }
    return p;
}

/* Solves with new data (the sense only at the first solve); returns DAQP's exit flag (1:
 * optimal) and its iterations in *iter. */
int peer_daqp_solve(peer_daqp *p, const double *H, const double *f, const double *A,
                    const double *bu, const double *bl, const int *sense, double *x, int *iter) {
    int n = p->qp.n, m = p->qp.m, ms = p->qp.ms, flag;
    memcpy(p->qp.H, H, sizeof(double) * n * n);
    memcpy(p->qp.f, f, sizeof(double) * n);
    memcpy(p->qp.A, A, sizeof(double) * (m - ms) * n);
    memcpy(p->qp.bupper, bu, sizeof(double) * m);
    memcpy(p->qp.blower, bl, sizeof(double) * m);
    if (!p->ready) {
        memcpy(p->qp.sense, sense, sizeof(int) * m);
        flag = setup_daqp(&p->qp, &p->work, NULL);
        if (flag < 0) return flag;
        p->ready = 1;
    } else {
        flag = daqp_update_ldp(DAQP_UPDATE_Rinv | DAQP_UPDATE_M | DAQP_UPDATE_v | DAQP_UPDATE_d,
                               &p->work, &p->qp);
        if (flag < 0) return flag;
    }
    daqp_solve(&p->res, &p->work);
    memcpy(x, p->res.x, sizeof(double) * n);
    *iter = p->res.iter;
    return p->res.exitflag;
}

void peer_daqp_free(peer_daqp *p) {
    if (!p) return;
    if (p->ready) {
        free_daqp_workspace(&p->work);
        free_daqp_ldp(&p->work);
    }
    free(p->qp.H); free(p->qp.f); free(p->qp.A); free(p->qp.bupper); free(p->qp.blower);
    free(p->qp.sense); free(p->res.x); free(p->res.lam);
    free(p);
}
