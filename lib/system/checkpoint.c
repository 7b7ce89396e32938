/* libodhs - the system's checkpoint section SYS: box, strain, positions,
 * radii, species labels (include/odhs/checkpoint.h, lib/io/ckpt.h). */
#include <math.h>
#include <string.h>

#include "io/ckpt.h"
#include "system/system.h"

void odhs__ckpt_write_system(odhs__wbuf *b, const odhs_system *sys)
{
    size_t n = sys->n;
    odhs__put_tag(b, "SYS ");
    odhs__put_u64(b, (uint64_t)sys->dim);
    odhs__put_u64(b, n);
    odhs__put_f64s(b, sys->L, 3);
    odhs__put_f64(b, sys->gamma);
    odhs__put_f64s(b, sys->x, n * (size_t)sys->dim);
    odhs__put_f64s(b, sys->r, n);
    odhs__put(b, sys->species, n * sizeof *sys->species);
}

/* the values the system setters accept */
static int check_system(odhs__ckpt_in *in, odhs_system *sys)
{
    size_t n = sys->n, dim = (size_t)sys->dim, nd = n * dim;
    if (!odhs__finite_all(sys->L, 3) || !isfinite(sys->gamma) || !odhs__finite_all(sys->x, nd) ||
        !odhs__finite_all(sys->r, n))
        return odhs__ckpt_bad(in, "checkpoint: non-finite number in the system section");
    double rmax = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (!(sys->r[i] > 0.0)) return odhs__ckpt_bad(in, "checkpoint: radius %zu is not positive", i);
        rmax = fmax(rmax, sys->r[i]);
        sys->species[i][ODHS_SPECIES_MAX] = '\0';
    }
    for (size_t k = 0; k < dim; ++k)
        if (!(sys->L[k] >= 4.0 * rmax)) return odhs__ckpt_bad(in, "checkpoint: box edge %zu too small", k);
    /* the aspect-ratio rule of the system setters (lib/system/system.c,
     * check_box): an XYZ file of a box outside it could not be read back
     * (found by fuzz_checkpoint) */
    if (!(sys->L[0] / sys->L[1] > 1e-100 && sys->L[0] / sys->L[1] < 1e100))
        return odhs__ckpt_bad(in, "checkpoint: box aspect ratio Lx/Ly = %g out of range [1e-100, 1e100]",
                              sys->L[0] / sys->L[1]);
    if (fabs(sys->gamma) > 0.5 * sys->L[0] / sys->L[1] * (1 + 1e-12))
        return odhs__ckpt_bad(in, "checkpoint: strain outside its remapped range");
    for (size_t i = 0; i < nd; ++i)
        if (sys->x[i] < 0.0 || sys->x[i] >= sys->L[i % dim])
            return odhs__ckpt_bad(in, "checkpoint: position outside the box");
    /* species labels as odhs_system_set_species accepts them (an empty or
     * blank label made an XYZ file that could not be read back: found by
     * fuzz_checkpoint); the bytes after the terminator are kept */
    for (size_t i = 0; i < n; ++i) {
        char lab[ODHS_SPECIES_MAX + 1];
        memcpy(lab, sys->species[i], sizeof lab);
        if (odhs_system_set_species(sys, i, lab))
            return odhs__ckpt_bad(in, "checkpoint: species label of particle %zu is not valid", i);
    }
    sys->rmax = rmax;
    sys->has_r = sys->has_x = 1;
    return ODHS_OK;
}

int odhs__ckpt_read_system(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    if (odhs__get_tag(b, "SYS ")) return odhs__ckpt_bad(in, "checkpoint: system section missing");
    uint64_t dim = odhs__get_u64(b), n = odhs__get_u64(b);
    if (b->bad || (dim != 2 && dim != 3) || n == 0 || n > (in->size / 8) / (dim + 1))
        return odhs__ckpt_bad(in, "checkpoint: bad dimension or particle count");
    int s = odhs_system_create((int)dim, (size_t)n, &in->sys);
    if (s) return odhs__ckpt_status(in, s);
    odhs_system *sys = in->sys;
    odhs__get_f64s(b, sys->L, 3);
    sys->gamma = odhs__get_f64(b);
    odhs__get_f64s(b, sys->x, (size_t)n * (size_t)dim);
    odhs__get_f64s(b, sys->r, (size_t)n);
    odhs__get(b, sys->species, (size_t)n * sizeof *sys->species);
    if (b->bad) return odhs__ckpt_bad(in, "checkpoint: system section truncated");
    return check_system(in, sys);
}

/* no optional sections of the system after the contacts yet (lib/io/ckpt.h) */
unsigned odhs__ckpt_write_system_tail(odhs__wbuf *b, const odhs__ckpt_out *o) { (void)b, (void)o; return 1; }
int odhs__ckpt_read_system_tail(odhs__ckpt_in *in, const char *tag) { (void)in, (void)tag; return 0; }
