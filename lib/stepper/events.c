/* libodhs - the step's contact changes and the events they make. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

int odhs__st_record_change(odhs_stepper *st, size_t i, size_t j, int delta)
{
    if (odhs__reserve((void **)&st->chg, &st->chgcap, st->nchg + 1, sizeof *st->chg)) return ODHS_E_NOMEM;
    st->chg[st->nchg].i = i < j ? i : j;
    st->chg[st->nchg].j = i < j ? j : i;
    st->chg[st->nchg].delta = delta;
    st->nchg++;
    return ODHS_OK;
}

/* ---- events ------------------------------------------------------------------ */
static int cmp_change(const void *a, const void *b)
{
    const odhs_change *x = a, *y = b;
    if (x->i != y->i) return x->i < y->i ? -1 : 1;
    if (x->j != y->j) return x->j < y->j ? -1 : 1;
    return 0;
}

/* the net events of the changes [lo, hi), appended */
static int collect_range(odhs_stepper *st, size_t lo, size_t hi)
{
    if (hi <= lo) return ODHS_OK;
    qsort(st->chg + lo, hi - lo, sizeof *st->chg, cmp_change);
    for (size_t a = lo; a < hi;) {
        size_t b = a;
        int sum = 0;
        while (b < hi && st->chg[b].i == st->chg[a].i && st->chg[b].j == st->chg[a].j) sum += st->chg[b++].delta;
        if (sum != 0) {
            if (odhs__reserve((void **)&st->ev, &st->evcap, st->nev + 1, sizeof *st->ev))
                return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
            odhs_event *e = &st->ev[st->nev++];
            e->kind = sum > 0 ? ODHS_EVENT_COLLISION : ODHS_EVENT_OPENING;
            e->i = st->chg[a].i;
            e->j = st->chg[a].j;
            e->time = st->time;
            e->strain = st->strain;
        }
        a = b;
    }
    return ODHS_OK;
}

/* turn the step's recorded changes into net events: those before the mark
 * (a batched step's contact problem) and those after it (its end) each net
 * on their own, so that a pair that closes within a batched step and opens
 * at its end is a collision and an opening, as in the exact scheme */
static int collect_events(odhs_stepper *st)
{
    const size_t mark = st->chg_mark < st->nchg ? st->chg_mark : st->nchg;
    st->nev = 0;
    int s = collect_range(st, 0, mark);
    if (!s) s = collect_range(st, mark, st->nchg);
    st->nchg = 0;
    st->chg_mark = 0;
    return s;
}

int odhs__st_emit_events(odhs_stepper *st, odhs_event *first, int *stop)
{
    int s = collect_events(st);
    if (s) return s;
    for (size_t k = 0; k < st->nev; ++k) {
        if (st->ev[k].kind == ODHS_EVENT_COLLISION) st->ncoll++;
        else st->nopen++;
    }
    if (first && st->nev) *first = st->ev[0];
    if (st->evfn)
        for (size_t k = 0; k < st->nev; ++k)
            if (st->evfn(&st->ev[k], st->evctx)) *stop = 1;
    return ODHS_OK;
}
