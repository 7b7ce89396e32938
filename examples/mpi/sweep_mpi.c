/* sweep_mpi - ensemble campaigns of sheared hard discs/spheres over MPI ranks.
 *
 * A campaign is a CSV file with one run per row (N, dim, phi or pressure,
 * seed, strain, driver). Each run builds the examples' bidisperse scene,
 * compresses it to phi, shears it at gammadot = 1 (fixed volume, or fixed
 * pressure) up to its strain, and writes its own directory under --out:
 *     runs/run_NNNN/series.csv    strain,shear_stress,pressure,z,phi,events
 *     runs/run_NNNN/checkpoint.odhs  the last checkpoint (removed when done)
 *     runs/run_NNNN/final.xyz     the final configuration
 *     runs/run_NNNN/result.csv    the run's averages (its presence = done)
 *     runs/run_NNNN/timing.txt    rank and wall time of each attempt
 * Rank 0 hands out runs one at a time (a rank that finishes asks for the next
 * run) and works on runs itself in between, answering requests from the
 * stepper's event callback. When all runs are done it writes runs.csv,
 * summary.csv (means and standard errors over seeds per state point) and the
 * plots eta_phi.svg and z_phi.svg.
 *
 * Re-launching the same command resumes: runs with a result are skipped, runs
 * with a checkpoint continue from it (their series is cut back to the
 * checkpoint), the others start over. Results are bit-identical to an
 * uninterrupted run with the stateless solvers (cholmod, cg, dense, spqr).
 *
 * Build (Open MPI):  mpicc sweep_mpi.c $(pkg-config --cflags --libs odhs) -lm
 * Serial fallback:   cc -DSWEEP_NO_MPI sweep_mpi.c $(pkg-config --cflags --libs odhs) -lm
 * Run:               mpirun -np 4 ./sweep_mpi --campaign flowcurve.csv --out fc
 * See docs/campaigns.md.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

#ifndef SWEEP_NO_MPI
#include <mpi.h>
#endif

#include <odhs.h>

#include "../cli.h"

#ifdef SWEEP_NO_MPI
#define PROG "sweep_serial"
#else
#define PROG "sweep_mpi"
#endif
#define TAG_REQ 11
#define TAG_JOB 12
/* the imposed shear rate (results in strain are rate-invariant) */
#define GAMMADOT 1.0

/* ---- settings and the campaign ------------------------------------------ */

enum { DRIVER_VOLUME = 0, DRIVER_PRESSURE = 1 };
static const char *driver_name[] = {"volume", "pressure"};

typedef struct {
    unsigned long n, dim, seed;
    double phi, pressure, strain;
    int driver;
} run_spec;

typedef struct {
    const char *campaign, *out, *solver;
    double every, transient, checkpoint, dt;
    int quiet;
    run_spec *runs;
    int nruns;
    int rank, size;
} settings;

static const char *default_campaign =
    "# built-in demo campaign: 2D, N = 64, two packing fractions, two seeds\n"
    "n,dim,phi,pressure,seed,strain,driver\n"
    "64,2,0.70,,1,0.5,volume\n"
    "64,2,0.70,,2,0.5,volume\n"
    "64,2,0.76,,1,0.5,volume\n"
    "64,2,0.76,,2,0.5,volume\n";

/* the rank prefix of every message */
static int g_rank = 0;
#define LOG(...)                                                                                   \
    do {                                                                                           \
        fprintf(stderr, PROG "[%d]: ", g_rank);                                                    \
        fprintf(stderr, __VA_ARGS__);                                                              \
        fputc('\n', stderr);                                                                       \
    } while (0)

static void fatal_exit(int code)
{
#ifndef SWEEP_NO_MPI
    MPI_Abort(MPI_COMM_WORLD, code);
#endif
    exit(code);
}

/* Parse the campaign text. Returns 0, or -1 with a message in err. */
static int parse_campaign(const char *text, run_spec **out, int *nout, char *err, size_t errlen)
{
    enum { C_N, C_DIM, C_PHI, C_P, C_SEED, C_STRAIN, C_DRIVER, C_COUNT };
    static const char *names[C_COUNT] = {"n", "dim", "phi", "pressure", "seed", "strain", "driver"};
    int col[16], ncol = 0, have_header = 0, cap = 0, nr = 0, lineno = 0;
    run_spec *runs = NULL;
    const char *p = text;
    while (*p) {
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        char line[1024];
        ++lineno;
        if (len >= sizeof line) {
            snprintf(err, errlen, "line %d: too long", lineno);
            goto fail;
        }
        memcpy(line, p, len);
        line[len] = 0;
        p = eol ? eol + 1 : p + len;
        if (len && line[len - 1] == '\r') line[--len] = 0;
        char *s = line;
        while (*s == ' ' || *s == '\t') ++s;
        if (!*s || *s == '#') continue;
        /* split on commas */
        char *field[16];
        int nf = 0;
        for (char *q = s;; ++q) {
            if (nf == 16) {
                snprintf(err, errlen, "line %d: more than 16 fields", lineno);
                goto fail;
            }
            field[nf++] = q;
            q = strchr(q, ',');
            if (!q) break;
            *q = 0;
        }
        for (int k = 0; k < nf; ++k) { /* trim */
            char *f = field[k];
            while (*f == ' ' || *f == '\t') ++f;
            char *e = f + strlen(f);
            while (e > f && (e[-1] == ' ' || e[-1] == '\t')) *--e = 0;
            field[k] = f;
        }
        if (!have_header) {
            int seen[C_COUNT] = {0};
            for (int k = 0; k < nf; ++k) {
                col[k] = -1;
                for (int c = 0; c < C_COUNT; ++c)
                    if (!strcmp(field[k], names[c])) col[k] = c;
                if (col[k] < 0) {
                    snprintf(err, errlen, "line %d: unknown column '%s' (known: n,dim,phi,pressure,seed,strain,driver)",
                             lineno, field[k]);
                    goto fail;
                }
                if (seen[col[k]]++) {
                    snprintf(err, errlen, "line %d: column '%s' twice", lineno, field[k]);
                    goto fail;
                }
            }
            if (!seen[C_N] || !seen[C_PHI] || !seen[C_SEED] || !seen[C_STRAIN]) {
                snprintf(err, errlen, "line %d: the header needs at least the columns n, phi, seed, strain", lineno);
                goto fail;
            }
            ncol = nf;
            have_header = 1;
            continue;
        }
        if (nf != ncol) {
            snprintf(err, errlen, "line %d: %d fields, the header has %d", lineno, nf, ncol);
            goto fail;
        }
        run_spec r = {.n = 0, .dim = 2, .seed = 0, .phi = 0, .pressure = 0, .strain = 0, .driver = -1};
        for (int k = 0; k < nf; ++k) {
            const char *v = field[k];
            int bad = 0;
            switch (col[k]) {
            case C_N: bad = cli_ulong(v, &r.n) || r.n < 2 || r.n > 100000000ul; break;
            case C_DIM: bad = cli_ulong(v, &r.dim) || (r.dim != 2 && r.dim != 3); break;
            case C_PHI: bad = cli_double(v, &r.phi) || r.phi <= 0 || r.phi >= 1; break;
            case C_P: bad = *v && (cli_double(v, &r.pressure) || r.pressure < 0); break;
            case C_SEED: bad = cli_ulong(v, &r.seed); break;
            case C_STRAIN: bad = cli_double(v, &r.strain) || r.strain <= 0; break;
            case C_DRIVER:
                if (!strcmp(v, "volume")) r.driver = DRIVER_VOLUME;
                else if (!strcmp(v, "pressure")) r.driver = DRIVER_PRESSURE;
                else bad = *v != 0;
                break;
            }
            if (bad) {
                snprintf(err, errlen, "line %d: bad value '%s' for %s", lineno, v, names[col[k]]);
                goto fail;
            }
        }
        if (r.driver < 0) r.driver = r.pressure > 0 ? DRIVER_PRESSURE : DRIVER_VOLUME;
        if (r.driver == DRIVER_PRESSURE && !(r.pressure > 0)) {
            snprintf(err, errlen, "line %d: driver pressure needs a pressure > 0", lineno);
            goto fail;
        }
        if (r.driver == DRIVER_VOLUME && r.pressure != 0) {
            snprintf(err, errlen, "line %d: a pressure is given but the driver is volume", lineno);
            goto fail;
        }
        if (nr == cap) {
            cap = cap ? 2 * cap : 16;
            run_spec *nw = realloc(runs, (size_t)cap * sizeof *runs);
            if (!nw) {
                snprintf(err, errlen, "out of memory");
                goto fail;
            }
            runs = nw;
        }
        runs[nr++] = r;
    }
    if (!have_header || nr == 0) {
        snprintf(err, errlen, "no runs (a header line and at least one row are needed)");
        goto fail;
    }
    *out = runs;
    *nout = nr;
    return 0;
fail:
    free(runs);
    return -1;
}

/* ---- files ---------------------------------------------------------------- */

static int file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static int make_dir(const char *path)
{
    if (mkdir(path, 0777) == 0 || errno == EEXIST) return 0;
    return -1;
}

/* whole file into a NUL-terminated buffer (NULL on error) */
static char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        if (n + 1 >= cap) {
            char *nb = realloc(buf, cap *= 2);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb;
        }
        size_t got = fread(buf + n, 1, cap - 1 - n, f);
        n += got;
        if (got == 0) break;
    }
    if (buf && ferror(f)) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    if (buf) {
        buf[n] = 0;
        if (len) *len = n;
    }
    return buf;
}

/* write text to path atomically (temporary file, fsync, rename) */
static int write_atomic(const char *path, const char *text)
{
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) return -1;
    size_t len = strlen(text);
    int bad = fwrite(text, 1, len, f) != len;
    bad |= fflush(f) != 0;
    bad |= fsync(fileno(f)) != 0;
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path)) {
        remove(tmp);
        return -1;
    }
    return 0;
}

/* a growing string */
typedef struct {
    char *s;
    size_t len, cap;
} strbuf;

static void sb_printf(strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_printf(strbuf *b, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        size_t room = b->cap - b->len;
        int n = vsnprintf(b->s ? b->s + b->len : NULL, b->s ? room : 0, fmt, ap);
        va_end(ap);
        if (n < 0) return;
        if (b->s && (size_t)n < room) {
            b->len += (size_t)n;
            return;
        }
        size_t cap = b->cap ? b->cap : 1024;
        while (cap < b->len + (size_t)n + 1) cap *= 2;
        char *ns = realloc(b->s, cap);
        if (!ns) {
            LOG("out of memory");
            fatal_exit(1);
        }
        b->s = ns;
        b->cap = cap;
    }
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- the master: hands out run indices ----------------------------------- */

typedef struct {
    const settings *S;
    const unsigned char *todo; /* 1: the run still has to be done */
    int next;                  /* next candidate index */
    int active;                /* workers not yet told to stop */
    int done, failed;
} master_t;

static master_t *g_master = NULL; /* set on rank 0 while it hands out work */

static int master_take(master_t *m)
{
    while (m->next < m->S->nruns && !m->todo[m->next]) ++m->next;
    return m->next < m->S->nruns ? m->next++ : -1;
}

static void master_note(master_t *m, int idx, int status, int rank)
{
    if (idx < 0) return;
    ++m->done;
    if (status) ++m->failed;
    if (!m->S->quiet)
        LOG("run %d %s on rank %d (%d done this launch, %d failed)", idx, status ? "FAILED" : "finished",
            rank, m->done, m->failed);
}

/* Answer pending requests of workers: a request carries the run the worker
 * just finished (or -1) and its status; the answer is the next run or -1.
 * block: wait until every worker has been told to stop. */
static void master_serve(master_t *m, int block)
{
#ifndef SWEEP_NO_MPI
    while (m->active > 0) {
        MPI_Status stt;
        int msg[2], flag = 1;
        if (!block) {
            MPI_Iprobe(MPI_ANY_SOURCE, TAG_REQ, MPI_COMM_WORLD, &flag, &stt);
            if (!flag) return;
            MPI_Recv(msg, 2, MPI_INT, stt.MPI_SOURCE, TAG_REQ, MPI_COMM_WORLD, &stt);
        } else {
            MPI_Recv(msg, 2, MPI_INT, MPI_ANY_SOURCE, TAG_REQ, MPI_COMM_WORLD, &stt);
        }
        master_note(m, msg[0], msg[1], stt.MPI_SOURCE);
        int job = master_take(m);
        MPI_Send(&job, 1, MPI_INT, stt.MPI_SOURCE, TAG_JOB, MPI_COMM_WORLD);
        if (job < 0) --m->active;
    }
#else
    (void)m;
    (void)block;
#endif
}

/* the stepper's event callback on rank 0: serve the workers while computing */
static int serve_cb(const odhs_event *ev, void *ctx)
{
    (void)ev;
    (void)ctx;
    if (g_master) master_serve(g_master, 0);
    return 0;
}

/* ---- one run -------------------------------------------------------------- */

typedef struct {
    char dir[4096], series[4200], ckpt[4200], final[4200], result[4200], timing[4200];
} run_paths;

static void paths_of(const settings *S, int idx, run_paths *p)
{
    snprintf(p->dir, sizeof p->dir, "%s/runs/run_%04d", S->out, idx);
    snprintf(p->series, sizeof p->series, "%s/series.csv", p->dir);
    snprintf(p->ckpt, sizeof p->ckpt, "%s/checkpoint.odhs", p->dir);
    snprintf(p->final, sizeof p->final, "%s/final.xyz", p->dir);
    snprintf(p->result, sizeof p->result, "%s/result.csv", p->dir);
    snprintf(p->timing, sizeof p->timing, "%s/timing.txt", p->dir);
}

static const char *series_header = "strain,shear_stress,pressure,z,phi,events\n";

/* Keep the header and the first `rows` data rows of the series file. Returns
 * 0, or -1 if the file has fewer rows (or cannot be read). */
static int truncate_series(const char *path, long rows)
{
    size_t len;
    char *buf = read_all(path, &len);
    if (!buf) return -1;
    long want = rows + 1, seen = 0;
    size_t cut = 0;
    for (size_t i = 0; i < len && seen < want; ++i)
        if (buf[i] == '\n') {
            ++seen;
            cut = i + 1;
        }
    int ok = seen == want && !strncmp(buf, series_header, strlen(series_header));
    free(buf);
    if (!ok) return -1;
    return truncate(path, (off_t)cut) ? -1 : 0;
}

/* Compression from the random scene to phi (the examples' protocol). */
static int build_scene(const run_spec *r, odhs_solver *solver, odhs_system **out, char *err, size_t errlen)
{
    odhs_system *sys = NULL;
    int rc = cli_scene((int)r->dim, r->n, r->seed, r->phi, &sys);
    if (rc) {
        snprintf(err, errlen, "scene: %s", sys ? odhs_system_errmsg(sys) : odhs_strerror(rc));
        odhs_system_destroy(sys);
        return -1;
    }
    double phi0;
    odhs_system_packing_fraction(sys, &phi0);
    if (r->phi > phi0) {
        odhs_driver *drv = NULL;
        odhs_stepper *st = NULL;
        if ((rc = odhs_driver_create(&drv)) || (rc = odhs_driver_set_compression_rate(drv, 1.0)) ||
            (rc = odhs_stepper_create(sys, drv, solver, &st)) || (rc = odhs_stepper_set_dt(st, 1e-3))) {
            snprintf(err, errlen, "compression setup: %s", odhs_strerror(rc));
        } else {
            odhs_stepper_set_event_callback(st, serve_cb, NULL);
            rc = odhs_stepper_run_until_packing_fraction(st, r->phi);
            if (rc == 0) rc = odhs_stepper_correct(st);
            if (rc) snprintf(err, errlen, "compression to phi = %g: %s (%s)", r->phi, odhs_strerror(rc), odhs_stepper_errmsg(st));
        }
        odhs_stepper_destroy(st);
        odhs_driver_destroy(drv);
        if (rc) {
            odhs_system_destroy(sys);
            return -1;
        }
    }
    *out = sys;
    return 0;
}

typedef struct {
    long samples;
    double sigma, p, z, phi;
    unsigned long long events;
} run_stats;

/* Averages over the rows of the series with strain index k*every >= transient. */
static int series_stats(const settings *S, const char *path, run_stats *out, char *err, size_t errlen)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(err, errlen, "cannot read series.csv");
        return -1;
    }
    char line[512];
    long row = -1, k;
    run_stats s = {0, 0, 0, 0, 0, 0};
    while (fgets(line, sizeof line, f)) {
        if (row < 0) { /* header */
            row = 0;
            continue;
        }
        k = row++; /* sample k is at strain k*every */
        double g, sig, p, z, phi;
        unsigned long long ev;
        if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%llu", &g, &sig, &p, &z, &phi, &ev) != 6) {
            fclose(f);
            snprintf(err, errlen, "series.csv: bad row %ld", row);
            return -1;
        }
        s.events = ev;
        if ((double)k * S->every < S->transient * (1 - 1e-12)) continue;
        s.samples++;
        s.sigma += sig;
        s.p += p;
        s.z += z;
        s.phi += phi;
    }
    fclose(f);
    if (s.samples == 0) {
        snprintf(err, errlen, "no samples after the transient strain %g", S->transient);
        return -1;
    }
    s.sigma /= (double)s.samples;
    s.p /= (double)s.samples;
    s.z /= (double)s.samples;
    s.phi /= (double)s.samples;
    *out = s;
    return 0;
}

static const char *result_header = "status,samples,shear_stress,pressure,z,phi,eta,events,message\n";

static int write_result(const run_paths *P, int ok, const run_stats *s, const char *msg)
{
    char text[2048], clean[1024];
    size_t k = 0;
    for (const char *c = msg ? msg : ""; *c && k + 1 < sizeof clean; ++c)
        clean[k++] = (*c == ',' || *c == '\n' || *c == '\r' || *c == '"') ? ';' : *c;
    clean[k] = 0;
    if (ok)
        snprintf(text, sizeof text, "%sok,%ld,%.17g,%.17g,%.17g,%.17g,%.17g,%llu,\n", result_header, s->samples, s->sigma,
                 s->p, s->z, s->phi, s->sigma / GAMMADOT, s->events);
    else
        snprintf(text, sizeof text, "%sfailed,0,nan,nan,nan,nan,nan,0,%s\n", result_header, clean);
    return write_atomic(P->result, text);
}

static void write_row(FILE *f, odhs_stepper *st, odhs_system *sys)
{
    double g, s, p, z, phi;
    uint64_t steps, nc, no;
    odhs_stepper_strain(st, &g);
    odhs_stepper_shear_stress(st, &s);
    odhs_stepper_pressure(st, &p);
    odhs_stepper_coordination(st, &z);
    odhs_stepper_counts(st, &steps, &nc, &no);
    odhs_system_packing_fraction(sys, &phi);
    fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%llu\n", g, s, p, z, phi, (unsigned long long)(nc + no));
}

/* Do run idx (resuming from its checkpoint if there is one). Writes the
 * result file in every case it can; returns 0 if the run succeeded, 1 if it
 * failed (the reason is in its result file). */
static int run_one(const settings *S, int idx)
{
    const run_spec *r = &S->runs[idx];
    run_paths P;
    paths_of(S, idx, &P);
    char err[1024] = "";
    double t0 = now_s(), g_start = 0;
    int resumed = 0, ok = 0;
    odhs_solver *solver = NULL;
    odhs_system *sys = NULL;
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    FILE *series = NULL;
    long nsamples = (long)ceil(r->strain / S->every - 1e-9), k = 0;
    long ck = lround(S->checkpoint / S->every);
    if (ck < 1) ck = 1;
    int rc;

    if (make_dir(P.dir)) {
        snprintf(err, sizeof err, "cannot create the run directory: %s", strerror(errno));
        goto done;
    }
    if ((rc = odhs_solver_create_by_name(S->solver, &solver))) {
        snprintf(err, sizeof err, "solver %s: %s", S->solver, odhs_strerror(rc));
        goto done;
    }
    if (file_exists(P.ckpt)) {
        char cerr[512];
        rc = odhs_checkpoint_read(P.ckpt, solver, &sys, &drv, &st, cerr, sizeof cerr);
        double g = 0;
        if (rc == 0) {
            odhs_stepper_strain(st, &g);
            k = lround(g / S->every);
        }
        if (rc == 0 && k >= 1 && k < nsamples && fabs(g - (double)k * S->every) < 1e-6 * S->every &&
            truncate_series(P.series, k + 1) == 0 && (series = fopen(P.series, "a"))) {
            resumed = 1;
            g_start = g;
            if (!S->quiet) LOG("run %d: resuming from its checkpoint at strain %.4g (series cut back to %ld rows)", idx, g, k + 1);
        } else {
            LOG("run %d: unusable checkpoint (%s), starting over", idx, rc ? cerr : "does not match the series");
            odhs_stepper_destroy(st);
            odhs_driver_destroy(drv);
            odhs_system_destroy(sys);
            st = NULL, drv = NULL, sys = NULL;
            k = 0;
        }
    }
    if (!resumed) {
        if (!S->quiet) {
            char pstr[64] = "";
            if (r->driver == DRIVER_PRESSURE) snprintf(pstr, sizeof pstr, ", p = %g", r->pressure);
            LOG("run %d: %s, d = %lu, N = %lu, phi = %g%s, seed %lu, strain %g", idx, driver_name[r->driver], r->dim,
                r->n, r->phi, pstr, r->seed, r->strain);
        }
        if (build_scene(r, solver, &sys, err, sizeof err)) goto done;
        if ((rc = odhs_driver_create(&drv)) || (rc = odhs_driver_set_shear_rate(drv, GAMMADOT)) ||
            (r->driver == DRIVER_PRESSURE && (rc = odhs_driver_set_pressure(drv, r->pressure))) ||
            (rc = odhs_stepper_create(sys, drv, solver, &st)) || (rc = odhs_stepper_set_dt(st, S->dt))) {
            snprintf(err, sizeof err, "setup: %s", odhs_strerror(rc));
            goto done;
        }
        if ((rc = odhs_stepper_reset(st))) {
            snprintf(err, sizeof err, "start: %s (%s)", odhs_strerror(rc), odhs_stepper_errmsg(st));
            goto done;
        }
        if (!(series = fopen(P.series, "w"))) {
            snprintf(err, sizeof err, "cannot write series.csv: %s", strerror(errno));
            goto done;
        }
        fputs(series_header, series);
        write_row(series, st, sys);
    }
    odhs_stepper_set_event_callback(st, serve_cb, NULL);
    for (++k; k <= nsamples; ++k) {
        double target = fmin((double)k * S->every, r->strain);
        rc = odhs_stepper_run_until_strain(st, target);
        if (rc) {
            snprintf(err, sizeof err, "stopped at strain %.6g: %s (%s)", target, odhs_strerror(rc), odhs_stepper_errmsg(st));
            goto done;
        }
        write_row(series, st, sys);
        if (k % ck == 0 && k < nsamples) {
            /* the series up to this row is on disk before the checkpoint that
             * refers to it */
            if (fflush(series) || fsync(fileno(series))) {
                snprintf(err, sizeof err, "cannot write series.csv: %s", strerror(errno));
                goto done;
            }
            if ((rc = odhs_checkpoint_write(st, P.ckpt))) {
                snprintf(err, sizeof err, "checkpoint.odhs: %s (%s)", odhs_strerror(rc), odhs_stepper_errmsg(st));
                goto done;
            }
        }
        if (g_master) master_serve(g_master, 0);
    }
    if (fclose(series)) {
        series = NULL;
        snprintf(err, sizeof err, "cannot write series.csv");
        goto done;
    }
    series = NULL;
    if ((rc = odhs_xyz_write(sys, P.final))) {
        snprintf(err, sizeof err, "cannot write final.xyz: %s", odhs_system_errmsg(sys));
        goto done;
    }
    ok = 1;
done:;
    run_stats s = {0, 0, 0, 0, 0, 0};
    if (ok && series_stats(S, P.series, &s, err, sizeof err)) ok = 0;
    if (series) fclose(series);
    if (write_result(&P, ok, &s, err)) {
        LOG("run %d: cannot write %s: %s", idx, P.result, strerror(errno));
        fatal_exit(1);
    }
    remove(P.ckpt);
    FILE *tf = fopen(P.timing, "a");
    if (tf) {
        fprintf(tf, "rank %d pid %ld %s strain %.6g wall_s %.3f %s\n", S->rank, (long)getpid(),
                resumed ? "resumed_at" : "started_at", g_start, now_s() - t0, ok ? "ok" : "failed");
        fclose(tf);
    }
    if (!ok) LOG("run %d failed: %s", idx, err);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    odhs_solver_destroy(solver);
    return ok ? 0 : 1;
}

/* ---- summary --------------------------------------------------------------- */

typedef struct {
    int ok;
    run_stats s;
    char msg[1024];
} run_result;

static int read_result(const settings *S, int idx, run_result *R)
{
    run_paths P;
    paths_of(S, idx, &P);
    memset(R, 0, sizeof *R);
    char *buf = read_all(P.result, NULL);
    if (!buf) {
        snprintf(R->msg, sizeof R->msg, "no result file");
        return -1;
    }
    char *row = strchr(buf, '\n');
    row = row ? row + 1 : buf;
    double eta;
    char status[16];
    int pos = 0;
    if (sscanf(row, "%15[a-z],%ld,%lf,%lf,%lf,%lf,%lf,%llu,%n", status, &R->s.samples, &R->s.sigma, &R->s.p, &R->s.z,
               &R->s.phi, &eta, &R->s.events, &pos) != 8 ||
        pos == 0) {
        snprintf(R->msg, sizeof R->msg, "malformed result file");
        free(buf);
        return -1;
    }
    R->ok = !strcmp(status, "ok");
    char *m = row + pos, *e = strchr(m, '\n');
    if (e) *e = 0;
    snprintf(R->msg, sizeof R->msg, "%s", m);
    free(buf);
    return 0;
}

typedef struct {
    int first; /* index of the first run of the state point */
    int nok, nfail;
    double m[5], e[5]; /* sigma, p, z, eta, phi: mean, standard error */
} state_point;

static int same_state(const run_spec *a, const run_spec *b)
{
    return a->driver == b->driver && a->dim == b->dim && a->n == b->n &&
           (a->driver == DRIVER_VOLUME ? a->phi == b->phi : a->pressure == b->pressure);
}

/* nan-safe CSV number */
static void sb_num(strbuf *b, double x)
{
    if (isnan(x)) sb_printf(b, ",nan");
    else sb_printf(b, ",%.10g", x);
}

/* ---- plots ----------------------------------------------------------------- */

typedef struct {
    double x, y, err;
} plot_pt;

static double nice_step(double range, int target)
{
    double raw = range / target, mag = pow(10, floor(log10(raw))), f = raw / mag;
    return mag * (f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10);
}

/* A line plot with error bars: one series per group (points with the same
 * group id, already sorted by x). logy: logarithmic y axis. */
static int write_plot(const char *path, const char *title, const char *xlabel, const char *ylabel, int logy,
                      const plot_pt *pt, const int *group, int npt, char labels[][64], int ngroups, double refy,
                      const char *reflabel)
{
    static const char *colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf"};
    const double W = 560, H = 400, ml = 78, mr = 20, mt = 36, mb = 56;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int i = 0; i < npt; ++i) {
        double lo = pt[i].y - (isnan(pt[i].err) ? 0 : pt[i].err), hi = pt[i].y + (isnan(pt[i].err) ? 0 : pt[i].err);
        if (logy && lo <= 0) lo = pt[i].y * 0.5;
        xmin = fmin(xmin, pt[i].x), xmax = fmax(xmax, pt[i].x);
        ymin = fmin(ymin, lo), ymax = fmax(ymax, hi);
    }
    if (npt == 0 || (logy && ymin <= 0)) return -1;
    if (!isnan(refy)) ymin = fmin(ymin, refy), ymax = fmax(ymax, refy);
    if (xmax - xmin < 1e-9) xmin -= 0.01, xmax += 0.01;
    double xpad = 0.05 * (xmax - xmin);
    xmin -= xpad, xmax += xpad;
    double ylo, yhi;
    if (logy) {
        ylo = pow(10, floor(log10(ymin)));
        yhi = pow(10, ceil(log10(ymax)));
        if (yhi <= ylo * 1.0001) yhi = ylo * 10;
    } else {
        double pad = 0.08 * (ymax - ymin > 0 ? ymax - ymin : fabs(ymax) + 1);
        ylo = ymin - pad, yhi = ymax + pad;
    }
    double pw = W - ml - mr, ph = H - mt - mb;
#define XP(x) (ml + pw * ((x) - xmin) / (xmax - xmin))
#define YP(y) (logy ? mt + ph * (1 - (log10(y) - log10(ylo)) / (log10(yhi) - log10(ylo))) : mt + ph * (1 - ((y) - ylo) / (yhi - ylo)))
    strbuf b = {NULL, 0, 0};
    sb_printf(&b,
              "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" viewBox=\"0 0 %g %g\" "
              "font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
              W, H, W, H);
    sb_printf(&b, "<text x=\"%g\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">%s</text>\n", ml + pw / 2, title);
    /* ticks and grid */
    double xs = nice_step(xmax - xmin, 6);
    for (double x = ceil(xmin / xs) * xs; x <= xmax + 1e-12; x += xs) {
        double X = XP(x);
        sb_printf(&b, "<line x1=\"%.1f\" y1=\"%g\" x2=\"%.1f\" y2=\"%g\" stroke=\"#e4e4e4\"/>\n", X, mt, X, mt + ph);
        sb_printf(&b, "<line x1=\"%.1f\" y1=\"%g\" x2=\"%.1f\" y2=\"%g\" stroke=\"black\"/>\n", X, mt + ph, X, mt + ph + 5);
        sb_printf(&b, "<text x=\"%.1f\" y=\"%g\" text-anchor=\"middle\">%.*f</text>\n", X, mt + ph + 20,
                  xs < 0.01 ? 3 : xs < 0.1 ? 2 : 1, x);
    }
    if (logy) {
        for (double d = ylo; d <= yhi * 1.0001; d *= 10) {
            for (int m = 1; m < 10; ++m) {
                double y = d * m;
                if (y > yhi * 1.0001) break;
                double Y = YP(y);
                sb_printf(&b, "<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"%s\"/>\n", ml, Y, ml + pw, Y,
                          m == 1 ? "#d8d8d8" : "#f0f0f0");
                sb_printf(&b, "<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"black\"/>\n", ml - (m == 1 ? 6 : 3),
                          Y, ml, Y);
                if (m == 1) sb_printf(&b, "<text x=\"%g\" y=\"%.1f\" text-anchor=\"end\">%g</text>\n", ml - 9, Y + 4, y);
            }
        }
    } else {
        double ys = nice_step(yhi - ylo, 6);
        for (double y = ceil(ylo / ys) * ys; y <= yhi + 1e-12; y += ys) {
            double Y = YP(y);
            sb_printf(&b, "<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n", ml, Y, ml + pw, Y);
            sb_printf(&b, "<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"black\"/>\n", ml - 5, Y, ml, Y);
            sb_printf(&b, "<text x=\"%g\" y=\"%.1f\" text-anchor=\"end\">%.*f</text>\n", ml - 9, Y + 4,
                      ys < 0.1 ? 2 : ys < 1 ? 1 : 0, fabs(y) < 1e-12 ? 0.0 : y);
        }
    }
    sb_printf(&b, "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" stroke=\"black\"/>\n", ml, mt, pw, ph);
    sb_printf(&b, "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">%s</text>\n", ml + pw / 2, H - 14, xlabel);
    sb_printf(&b, "<text transform=\"translate(20,%g) rotate(-90)\" text-anchor=\"middle\">%s</text>\n", mt + ph / 2, ylabel);
    if (!isnan(refy)) {
        sb_printf(&b, "<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"#555\" stroke-dasharray=\"6,4\"/>\n", ml,
                  YP(refy), ml + pw, YP(refy));
        sb_printf(&b, "<text x=\"%g\" y=\"%.1f\" text-anchor=\"end\" fill=\"#555\">%s</text>\n", ml + pw - 6, YP(refy) + 16,
                  reflabel);
    }
    /* series */
    for (int g = 0; g < ngroups; ++g) {
        const char *c = colors[g % 6];
        sb_printf(&b, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"", c);
        for (int i = 0; i < npt; ++i)
            if (group[i] == g) sb_printf(&b, "%.1f,%.1f ", XP(pt[i].x), YP(pt[i].y));
        sb_printf(&b, "\"/>\n");
        for (int i = 0; i < npt; ++i) {
            if (group[i] != g) continue;
            double X = XP(pt[i].x), Y = YP(pt[i].y);
            if (!isnan(pt[i].err) && pt[i].err > 0) {
                double lo = pt[i].y - pt[i].err, hi = pt[i].y + pt[i].err;
                if (logy && lo <= ylo) lo = ylo;
                double Y0 = YP(lo), Y1 = YP(hi);
                sb_printf(&b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>\n", X, Y0, X, Y1, c);
                sb_printf(&b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>\n", X - 4, Y0, X + 4, Y0, c);
                sb_printf(&b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>\n", X - 4, Y1, X + 4, Y1, c);
            }
            sb_printf(&b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3.5\" fill=\"%s\"/>\n", X, Y, c);
        }
        /* legend at the bottom right (the curves rise with phi) */
        double ly = mt + ph - 14 - 18 * (ngroups - 1 - g);
        sb_printf(&b, "<circle cx=\"%g\" cy=\"%g\" r=\"3.5\" fill=\"%s\"/>\n", ml + pw - 14, ly - 4, c);
        sb_printf(&b, "<text x=\"%g\" y=\"%g\" text-anchor=\"end\">%s</text>\n", ml + pw - 24, ly, labels[g]);
    }
    sb_printf(&b, "</svg>\n");
#undef XP
#undef YP
    int rc = write_atomic(path, b.s);
    free(b.s);
    return rc;
}

/* runs.csv, summary.csv, the plots and a table on stdout. Returns the number
 * of failed runs, or -1 on a write error. */
static int write_summary(const settings *S)
{
    run_result *R = calloc((size_t)S->nruns, sizeof *R);
    int *sp_of = calloc((size_t)S->nruns, sizeof *sp_of);
    state_point *sp = calloc((size_t)S->nruns, sizeof *sp);
    if (!R || !sp_of || !sp) {
        LOG("out of memory");
        fatal_exit(1);
    }
    int nsp = 0, nfailed = 0;
    strbuf runs = {NULL, 0, 0}, sum = {NULL, 0, 0};
    sb_printf(&runs, "run,driver,dim,n,phi_set,pressure_set,seed,strain,status,samples,shear_stress,pressure,z,phi,eta,"
                     "events,message\n");
    for (int i = 0; i < S->nruns; ++i) {
        const run_spec *r = &S->runs[i];
        if (read_result(S, i, &R[i])) R[i].ok = 0;
        if (!R[i].ok) ++nfailed;
        sb_printf(&runs, "%d,%s,%lu,%lu,%.10g,%.10g,%lu,%.10g,%s,%ld", i, driver_name[r->driver], r->dim, r->n, r->phi,
                  r->pressure, r->seed, r->strain, R[i].ok ? "ok" : "failed", R[i].s.samples);
        if (R[i].ok) {
            sb_num(&runs, R[i].s.sigma), sb_num(&runs, R[i].s.p), sb_num(&runs, R[i].s.z), sb_num(&runs, R[i].s.phi);
            sb_num(&runs, R[i].s.sigma / GAMMADOT);
        } else {
            sb_printf(&runs, ",nan,nan,nan,nan,nan");
        }
        sb_printf(&runs, ",%llu,%s\n", R[i].s.events, R[i].msg);
        int j = 0;
        while (j < nsp && !same_state(&S->runs[sp[j].first], r)) ++j;
        if (j == nsp) sp[nsp++].first = i;
        sp_of[i] = j;
    }
    /* means and standard errors over the runs (seeds) of each state point */
    for (int j = 0; j < nsp; ++j) {
        for (int q = 0; q < 5; ++q) {
            double sum1 = 0, sum2 = 0;
            int n = 0;
            sp[j].nok = sp[j].nfail = 0;
            for (int i = 0; i < S->nruns; ++i) {
                if (sp_of[i] != j) continue;
                if (!R[i].ok) {
                    ++sp[j].nfail;
                    continue;
                }
                ++sp[j].nok;
                double v = q == 0 ? R[i].s.sigma : q == 1 ? R[i].s.p : q == 2 ? R[i].s.z : q == 3 ? R[i].s.sigma / GAMMADOT : R[i].s.phi;
                sum1 += v, ++n;
            }
            double mean = n ? sum1 / n : NAN;
            for (int i = 0; i < S->nruns; ++i)
                if (sp_of[i] == j && R[i].ok) {
                    double v = q == 0 ? R[i].s.sigma : q == 1 ? R[i].s.p : q == 2 ? R[i].s.z : q == 3 ? R[i].s.sigma / GAMMADOT : R[i].s.phi;
                    sum2 += (v - mean) * (v - mean);
                }
            sp[j].m[q] = mean;
            sp[j].e[q] = n > 1 ? sqrt(sum2 / (n - 1) / n) : NAN;
        }
    }
    sb_printf(&sum, "driver,dim,n,phi_set,pressure_set,runs_ok,runs_failed,shear_stress,shear_stress_err,pressure,"
                    "pressure_err,z,z_err,eta,eta_err,phi,phi_err\n");
    printf("%-8s %3s %7s %7s %8s %4s %4s %22s %22s %17s %22s\n", "driver", "dim", "N", "phi", "p_set", "ok", "fail",
           "eta (+- s.e.)", "pressure", "z", "phi (mean)");
    for (int j = 0; j < nsp; ++j) {
        const run_spec *r = &S->runs[sp[j].first];
        sb_printf(&sum, "%s,%lu,%lu,%.10g,%.10g,%d,%d", driver_name[r->driver], r->dim, r->n,
                  r->driver == DRIVER_VOLUME ? r->phi : NAN, r->pressure, sp[j].nok, sp[j].nfail);
        for (int q = 0; q < 5; ++q) sb_num(&sum, sp[j].m[q]), sb_num(&sum, sp[j].e[q]);
        sb_printf(&sum, "\n");
        printf("%-8s %3lu %7lu %7.4f %8.4g %4d %4d %11.4g +- %-7.2g %11.4g +- %-7.2g %6.3f +- %-6.2g %11.5f +- %-7.2g\n",
               driver_name[r->driver], r->dim, r->n, r->phi, r->pressure, sp[j].nok, sp[j].nfail, sp[j].m[3], sp[j].e[3],
               sp[j].m[1], sp[j].e[1], sp[j].m[2], sp[j].e[2], sp[j].m[4], sp[j].e[4]);
    }
    char path[4200];
    int bad = 0;
    snprintf(path, sizeof path, "%s/runs.csv", S->out);
    bad |= write_atomic(path, runs.s);
    snprintf(path, sizeof path, "%s/summary.csv", S->out);
    bad |= write_atomic(path, sum.s);

    /* plots: volume-driven state points with results, one curve per (dim, N) */
    plot_pt *pe = calloc((size_t)nsp + 1, sizeof *pe), *pz = calloc((size_t)nsp + 1, sizeof *pz);
    int *grp = calloc((size_t)nsp + 1, sizeof *grp);
    char(*labels)[64] = calloc(6, sizeof *labels);
    unsigned long gkey[6][2];
    int ngr = 0, npt = 0;
    if (!pe || !pz || !grp || !labels) {
        LOG("out of memory");
        fatal_exit(1);
    }
    for (int g = 0; g < 6; ++g) {
        /* collect the next group in order of first appearance */
        int found = 0;
        for (int j = 0; j < nsp && !found; ++j) {
            const run_spec *r = &S->runs[sp[j].first];
            if (r->driver != DRIVER_VOLUME || sp[j].nok == 0) continue;
            int known = 0;
            for (int h = 0; h < ngr; ++h) known |= gkey[h][0] == r->dim && gkey[h][1] == r->n;
            if (known) continue;
            gkey[ngr][0] = r->dim, gkey[ngr][1] = r->n;
            snprintf(labels[ngr], 64, "%luD, N = %lu", r->dim, r->n);
            found = 1;
        }
        if (!found) break;
        int start = npt;
        for (int j = 0; j < nsp; ++j) {
            const run_spec *r = &S->runs[sp[j].first];
            if (r->driver != DRIVER_VOLUME || sp[j].nok == 0 || r->dim != gkey[ngr][0] || r->n != gkey[ngr][1]) continue;
            pe[npt] = (plot_pt){r->phi, sp[j].m[3], sp[j].e[3]};
            pz[npt] = (plot_pt){r->phi, sp[j].m[2], sp[j].e[2]};
            grp[npt++] = ngr;
        }
        /* sort the group's points by phi (insertion sort) */
        for (int a = start + 1; a < npt; ++a)
            for (int c = a; c > start && pe[c].x < pe[c - 1].x; --c) {
                plot_pt t = pe[c];
                pe[c] = pe[c - 1], pe[c - 1] = t;
                t = pz[c];
                pz[c] = pz[c - 1], pz[c - 1] = t;
            }
        ++ngr;
    }
    if (npt > 0) {
        snprintf(path, sizeof path, "%s/eta_phi.svg", S->out);
        if (write_plot(path, "Shear viscosity at fixed volume (mean \u00b1 s.e. over seeds)", "packing fraction \u03c6",
                       "\u03b7 = \u03c3<tspan baseline-shift=\"sub\" font-size=\"10\">xy</tspan> / \u03b3\u0307   [1/\u03be<tspan baseline-shift=\"sub\" font-size=\"10\">0</tspan>]", 1, pe, grp, npt, labels, ngr, NAN, ""))
            LOG("no eta(phi) plot (non-positive viscosities)");
        snprintf(path, sizeof path, "%s/z_phi.svg", S->out);
        int dim0 = (int)gkey[0][0], same = 1;
        for (int h = 1; h < ngr; ++h) same &= (int)gkey[h][0] == dim0;
        bad |= write_plot(path, "Mean coordination at fixed volume (mean \u00b1 s.e. over seeds)", "packing fraction \u03c6",
                          "z = 2 N<tspan baseline-shift=\"sub\" font-size=\"10\">c</tspan> / N", 0, pz, grp, npt, labels, ngr, same ? 2.0 * dim0 : NAN,
                          "isostatic z = 2d (jamming)");
    }
    free(pe), free(pz), free(grp), free(labels);
    free(runs.s), free(sum.s), free(R), free(sp_of), free(sp);
    return bad ? -1 : nfailed;
}

/* ---- main ------------------------------------------------------------------- */

int main(int argc, char **argv)
{
    settings S = {.campaign = NULL, .out = "sweep_out", .solver = NULL, .every = 0.01, .transient = 0.2,
                  .checkpoint = 0.1, .dt = 1e-3, .quiet = 0, .runs = NULL, .nruns = 0, .rank = 0, .size = 1};
#ifndef SWEEP_NO_MPI
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &S.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &S.size);
#endif
    g_rank = S.rank;
    const cli_opt opts[] = {
        CLI_OPT_STRING("--campaign", &S.campaign, "FILE.csv",
                       "runs, one per row; header names the columns n,dim,phi,pressure,seed,strain,driver (any "
                       "order; dim defaults to 2, driver to volume, or to pressure when a pressure is given); driver "
                       "volume shears at fixed volume at phi, driver pressure compresses to phi and shears at fixed "
                       "pressure",
                       .deftext = "4 built-in runs, N = 64, phi 0.70/0.76, 2 seeds"),
        CLI_OPT_STRING("--out", &S.out, "DIR",
                       "output directory; re-running the same command resumes the campaign found there", CLI_ANY),
        CLI_EVERY(&S.every, "strain"),
        CLI_OPT_DOUBLE("--transient", &S.transient, "X", "strain discarded before averaging", CLI_NONNEGATIVE),
        CLI_OPT_DOUBLE("--checkpoint", &S.checkpoint, "X", "strain between checkpoints, rounded to a multiple of --every",
                       CLI_POSITIVE),
        CLI_DT(&S.dt, "strain units"),
        /* not auto: a run resumed from a checkpoint must equal an unbroken one
         * bit for bit, and only stateless solvers continue so (auto and
         * cholmod-pcg keep state that the checkpoint does not hold) */
        CLI_OPT_STRING("--solver", &S.solver, "NAME", CLI_SOLVER_HELP,
                       .deftext = "cholmod when built in, else cg: resumed runs are bit-identical only with a "
                                  "stateless solver"),
        CLI_OPT_FLAG("--quiet", &S.quiet, "no per-run progress lines"),
        CLI_END,
    };
    const cli_spec cli = {
        PROG, "[options]   (under MPI: mpirun -np R sweep_mpi [options])", opts,
        "cholmod-pcg works but keeps state, so a resumed run is then not bit-identical.\n"
        "Units: lengths in small-particle diameters, gammadot = 1, xi0 = 1; stresses in\n"
        "gammadot/xi0 (2D: per length, 3D: per area); eta = sigma_xy/gammadot.\n"
        "Exit status: 0 all runs ok, 3 campaign complete but some runs failed (see\n"
        "runs.csv), 1 fatal error, 2 bad usage or campaign file.\n",
        S.rank != 0};
    /* status: 0 go on, -1 after --help (exit 0), else the exit status */
    int status = cli_parse(&cli, argc, argv);
    status = status == CLI_GO ? 0 : status == 0 ? -1 : status;
    if (!S.solver) {
        odhs_solver *s;
        S.solver = odhs_solver_create_by_name("cholmod", &s) == ODHS_OK ? "cholmod" : "cg";
        if (!strcmp(S.solver, "cholmod")) odhs_solver_destroy(s);
    } else if (status == 0) {
        odhs_solver *s;
        int rc = odhs_solver_create_by_name(S.solver, &s);
        if (rc) {
            if (S.rank == 0) fprintf(stderr, PROG ": solver %s: %s\n", S.solver, odhs_strerror(rc)), cli_usage(&cli, stderr);
            status = 2;
        } else {
            odhs_solver_destroy(s);
        }
    }

    /* Rank 0 reads the campaign, checks the output directory and sends the
     * campaign text to every rank. */
    char *text = NULL;
#ifndef SWEEP_NO_MPI
    int textlen = 0;
#endif
    unsigned char *todo = NULL;
    if (S.rank == 0 && status == 0) {
        if (S.campaign) {
            size_t len;
            text = read_all(S.campaign, &len);
            if (!text) {
                fprintf(stderr, PROG ": cannot read %s: %s\n", S.campaign, strerror(errno));
                status = 1;
            } else if (len > (1u << 30)) {
                fprintf(stderr, PROG ": %s is too large\n", S.campaign);
                status = 1;
            }
        } else {
            text = strdup(default_campaign);
        }
        if (status == 0) {
            char err[512];
            if (parse_campaign(text, &S.runs, &S.nruns, err, sizeof err)) {
                fprintf(stderr, PROG ": %s: %s\n", S.campaign ? S.campaign : "built-in campaign", err);
                status = 2;
            } else {
                for (int i = 0; i < S.nruns && !status; ++i)
                    if (!(S.runs[i].strain > S.transient)) {
                        fprintf(stderr, PROG ": run %d: strain %g is not beyond the transient %g (--transient)\n", i,
                                S.runs[i].strain, S.transient);
                        status = 2;
                    }
            }
        }
        /* the campaign's identity: settings that change results + the CSV */
        if (status == 0) {
            strbuf id = {NULL, 0, 0};
            sb_printf(&id, "sweep_mpi campaign 1\nlibodhs %s\nsolver %s\nevery %.17g\ntransient %.17g\ncheckpoint %.17g\n"
                           "dt %.17g\n--- campaign ---\n%s",
                      odhs_version_string(), S.solver, S.every, S.transient, S.checkpoint, S.dt, text);
            char path[4200], runsdir[4200];
            snprintf(path, sizeof path, "%s/campaign.txt", S.out);
            snprintf(runsdir, sizeof runsdir, "%s/runs", S.out);
            char *old = read_all(path, NULL);
            if (make_dir(S.out) || make_dir(runsdir)) {
                fprintf(stderr, PROG ": cannot create %s: %s\n", runsdir, strerror(errno));
                status = 1;
            } else if (old && strcmp(old, id.s)) {
                fprintf(stderr,
                        PROG ": %s holds a different campaign (campaign file or settings differ from %s); use "
                             "another --out or delete it\n",
                        S.out, path);
                status = 1;
            } else if (!old && write_atomic(path, id.s)) {
                fprintf(stderr, PROG ": cannot write %s: %s\n", path, strerror(errno));
                status = 1;
            }
            free(old);
            free(id.s);
        }
        if (status == 0) {
            int pending = 0;
            todo = calloc((size_t)S.nruns, 1);
            for (int i = 0; i < S.nruns; ++i) {
                run_paths P;
                paths_of(&S, i, &P);
                todo[i] = !file_exists(P.result);
                pending += todo[i];
                if (!todo[i]) remove(P.ckpt); /* left by a kill just after the result */
            }
            LOG("%d runs, %d already done, %d to do on %d rank%s (solver %s, output in %s)", S.nruns, S.nruns - pending,
                pending, S.size, S.size > 1 ? "s" : "", S.solver, S.out);
        }
#ifndef SWEEP_NO_MPI
        textlen = text ? (int)strlen(text) : 0;
#endif
    }
#ifndef SWEEP_NO_MPI
    MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
#endif
    if (status) {
#ifndef SWEEP_NO_MPI
        MPI_Finalize();
#endif
        return status < 0 ? 0 : status;
    }
#ifndef SWEEP_NO_MPI
    MPI_Bcast(&textlen, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (S.rank != 0) {
        text = malloc((size_t)textlen + 1);
        if (!text) fatal_exit(1);
    }
    MPI_Bcast(text, textlen + 1, MPI_CHAR, 0, MPI_COMM_WORLD);
    if (S.rank != 0) {
        char err[512];
        if (parse_campaign(text, &S.runs, &S.nruns, err, sizeof err)) {
            LOG("campaign: %s", err);
            fatal_exit(1);
        }
    }
#endif

    double t0 = now_s();
    int failed_here = 0, done_here = 0;
    if (S.rank == 0) {
        master_t m = {.S = &S, .todo = todo, .next = 0, .active = S.size - 1, .done = 0, .failed = 0};
        g_master = &m;
        int job;
        while ((job = master_take(&m)) >= 0) {
            int st = run_one(&S, job);
            master_note(&m, job, st, 0);
            failed_here += st, ++done_here;
            master_serve(&m, 0);
        }
        master_serve(&m, 1); /* until every worker has been told to stop */
        g_master = NULL;
        LOG("all runs done: %d this launch (%d failed), %.2f s wall", m.done, m.failed, now_s() - t0);
        int nf = write_summary(&S);
        if (nf < 0) {
            LOG("cannot write the summary in %s: %s", S.out, strerror(errno));
            status = 1;
        } else {
            LOG("summary: %s/summary.csv, runs: %s/runs.csv%s", S.out, S.out, nf ? " (some runs failed)" : "");
            status = nf ? 3 : 0;
        }
    } else {
#ifndef SWEEP_NO_MPI
        int msg[2] = {-1, 0}, job;
        for (;;) {
            MPI_Send(msg, 2, MPI_INT, 0, TAG_REQ, MPI_COMM_WORLD);
            MPI_Recv(&job, 1, MPI_INT, 0, TAG_JOB, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            if (job < 0) break;
            msg[0] = job;
            msg[1] = run_one(&S, job);
            failed_here += msg[1], ++done_here;
        }
        if (!S.quiet) LOG("no more runs: %d done on this rank (%d failed), %.2f s", done_here, failed_here, now_s() - t0);
#endif
    }
    free(todo);
    free(text);
    free(S.runs);
#ifndef SWEEP_NO_MPI
    MPI_Finalize();
#endif
    return status;
}
