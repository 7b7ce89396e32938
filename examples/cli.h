/* cli.h - what the example programs share: the option table, its parser and
 * its --help printer, the options several examples take, number parsing, the
 * built-in scene and the checks of the files and solver named on the command
 * line (header-only, so each example stays one file to build:
 * cc example.c $(pkg-config --cflags --libs odhs) -lm).
 *
 * An example lists its options in a table ended by CLI_END, the common ones
 * by the macros below so that they read the same in every --help:
 *
 *     const cli_opt opts[] = {
 *         CLI_IN(&in),
 *         CLI_OPT_DOUBLE("--strain", &strain, "X", "total strain", CLI_POSITIVE),
 *         CLI_N(&n),
 *         CLI_END,
 *     };
 *     const cli_spec cli = {"prog", NULL, opts, "footer lines\n", 0};
 *     int rc = cli_parse(&cli, argc, argv);
 *     if (rc != CLI_GO) return rc;
 *
 * The command-line contract every example keeps: --help (or -h) prints the
 * usage to stdout and exits 0; an unknown option, a missing value or a bad
 * value prints a message and the usage to stderr and exits 2; options are
 * read in order, the last one wins; a value is the next argument, whatever
 * it looks like. The usage shows each option's default as the variable holds
 * it before the command line is read.
 *
 * The defaults are the library's: the adaptive Heun scheme and the "auto"
 * solver. The paper's scheme ("paper mode") is --integrator euler --solver cg.
 * An example that includes this header defines _POSIX_C_SOURCE first (for
 * isatty and fileno, used by the progress line). */
#ifndef ODHS_EXAMPLES_CLI_H
#define ODHS_EXAMPLES_CLI_H

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <time.h>
#include <unistd.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <odhs.h>

#include "plot.h"

/* a finite double taking the whole string; 0 on success */
static inline int cli_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

/* a non-negative integer taking the whole string; 0 on success */
static inline int cli_ulong(const char *s, unsigned long *out)
{
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || end == s || *end || s[0] == '-') return -1;
    *out = v;
    return 0;
}

/* ---- the option table ------------------------------------------------------ */

/* what an option's value is, and what cli_opt.value points to */
enum {
    CLI_INT,    /* int: a non-negative integer                              */
    CLI_ULONG,  /* unsigned long: counts and seeds                          */
    CLI_DOUBLE, /* double: a finite number                                  */
    CLI_STRING, /* const char *: the argument itself (a file, a name)       */
    CLI_FLAG,   /* int: set to 1, takes no value                            */
    CLI_LIST    /* int: the index of the value in cli_opt.choices           */
};

/* cli_opt.bounds: which of lo < x, lo <= x, x < hi, x <= hi a number must meet */
enum { CLI_GT = 1, CLI_GE = 2, CLI_LT = 4, CLI_LE = 8 };

typedef struct {
    const char *name;           /* "--dt"; NULL ends the table (CLI_END)        */
    int kind;                   /* CLI_INT ... CLI_LIST                          */
    void *value;                /* the variable, holding the default            */
    const char *arg;            /* the value in the usage: "X", "FILE.xyz"      */
    const char *help;           /* one sentence, wrapped by the printer         */
    int bounds;                 /* CLI_GT | CLI_LE ...: the range of a number   */
    double lo, hi;              /* its ends                                      */
    const char *const *choices; /* CLI_LIST: the accepted values, NULL-ended    */
    const char *deftext;        /* the default in words instead of the value
                                 * (a string option: only while it is NULL);
                                 * "": show no default                           */
} cli_opt;

typedef struct {
    const char *prog;     /* in the usage line and in every message          */
    const char *synopsis; /* after "usage: PROG "; NULL: "[options]"          */
    const cli_opt *opts;  /* the table, ended by CLI_END                      */
    const char *footer;   /* lines printed after the options; NULL: none      */
    int mute;             /* print nothing (MPI ranks other than 0)           */
} cli_spec;

/* cli_parse: go on with the program (any other value is its exit status) */
#define CLI_GO (-1)

/* The ranges, as the last argument of CLI_OPT_*: */
#define CLI_ANY .bounds = 0
#define CLI_POSITIVE .bounds = CLI_GT, .lo = 0        /* x > 0       */
#define CLI_NONNEGATIVE .bounds = CLI_GE, .lo = 0     /* x >= 0      */
#define CLI_ABOVE(a) .bounds = CLI_GT, .lo = (a)      /* x > a       */
#define CLI_ATLEAST(a) .bounds = CLI_GE, .lo = (a)    /* x >= a      */
#define CLI_ATMOST(b) .bounds = CLI_LE, .hi = (b)     /* x <= b      */
#define CLI_OPEN(a, b) .bounds = CLI_GT | CLI_LT, .lo = (a), .hi = (b)  /* a < x < b   */
#define CLI_ABOVE_ATMOST(a, b) .bounds = CLI_GT | CLI_LE, .lo = (a), .hi = (b) /* a < x <= b  */
#define CLI_BETWEEN(a, b) .bounds = CLI_GE | CLI_LE, .lo = (a), .hi = (b)    /* a <= x <= b */

/* A table entry; the pointer must have the kind's type (checked by the
 * compiler). The trailing arguments are designators: a range above, and
 * .deftext = "..." where wanted. */
#define CLI_PTR_(type, p) ((void *)(1 ? (p) : (type *)0))
#define CLI_OPT_INT(name, p, arg, help, ...) {name, CLI_INT, CLI_PTR_(int, p), arg, help, __VA_ARGS__}
#define CLI_OPT_ULONG(name, p, arg, help, ...) {name, CLI_ULONG, CLI_PTR_(unsigned long, p), arg, help, __VA_ARGS__}
#define CLI_OPT_DOUBLE(name, p, arg, help, ...) {name, CLI_DOUBLE, CLI_PTR_(double, p), arg, help, __VA_ARGS__}
#define CLI_OPT_STRING(name, p, arg, help, ...) {name, CLI_STRING, CLI_PTR_(const char *, p), arg, help, __VA_ARGS__}
#define CLI_OPT_FLAG(name, p, help) {name, CLI_FLAG, CLI_PTR_(int, p), NULL, help, .bounds = 0}
#define CLI_OPT_LIST(name, p, arg, help, list, ...)                                                                  \
    {name, CLI_LIST, CLI_PTR_(int, p), arg, help, .choices = (list), __VA_ARGS__}
#define CLI_END {.name = NULL}

/* ---- the options several examples take ------------------------------------- */

/* the integrators of the stepper, by index (--integrator) */
static const char *const cli_integrators[] = {"euler", "heun", "batched", NULL};
#define CLI_DEFAULT_INTEGRATOR ODHS_INTEGRATOR_HEUN /* the library's default */
#define CLI_DEFAULT_SOLVER "auto"                   /* the library's automatic choice */
_Static_assert(ODHS_INTEGRATOR_EULER == 0 && ODHS_INTEGRATOR_HEUN == 1 && ODHS_INTEGRATOR_BATCHED == 2,
               "cli_integrators is indexed by the enum");

#define CLI_SOLVER_HELP                                                                                              \
    "linear solver: auto (a direct or preconditioned solver chosen by size, with fallbacks), cg, dense, cholmod, "   \
    "cholmod-pcg, spqr; paper mode: cg"

#define CLI_IN(p)                                                                                                    \
    CLI_OPT_STRING("--in", p, "FILE.xyz", "start from a configuration file (extended XYZ, or a LAMMPS data file: " \
                   ".data, .lmp) instead of the built-in scene", CLI_ANY)
#define CLI_OUT(p)                                                                                                   \
    CLI_OPT_STRING("--out", p, "FILE.xyz",                                                                           \
                   "write the final configuration (extended XYZ; a LAMMPS data file when named .data or .lmp)",     \
                   CLI_ANY)
#define CLI_SVG(p)                                                                                                   \
    CLI_OPT_STRING("--svg", p, "FILE.svg",                                                                           \
                   "picture of the final state: discs coloured by size, contact forces as lines of width "           \
                   "proportional to the force",                                                                      \
                   CLI_ANY)
/* columns: the CSV header line, also given to cli_series */
#define CLI_SERIES(p, columns) CLI_OPT_STRING("--series", p, "FILE.csv", "write " columns " per output interval", CLI_ANY)
#define CLI_SOLVER(p) CLI_OPT_STRING("--solver", p, "NAME", CLI_SOLVER_HELP, CLI_ANY)
#define CLI_INTEGRATOR(p)                                                                                            \
    CLI_OPT_LIST("--integrator", p, "NAME", "heun (adaptive, steps of at most --dt), euler (the paper's fixed step " \
                 "--dt; paper mode: --integrator euler --solver cg) or batched (steps not cut at collisions, many " \
                 "events per step: large N)", cli_integrators, CLI_ANY)
/* 0 keeps the integrator's own default (odhs_stepper_set_tolerance) */
#define CLI_TOL(p)                                                                                                   \
    CLI_OPT_DOUBLE("--tol", p, "X", "heun, batched: error per step relative to the mean diameter", CLI_OPEN(0, 1),  \
                   .deftext = "the integrator's: 1e-6 heun, 1e-3 batched")
/* set the tolerance given with --tol (0: the integrator's default) */
static inline int cli_set_tolerance(odhs_stepper *st, double tol)
{
    return tol > 0.0 ? odhs_stepper_set_tolerance(st, tol) : ODHS_OK;
}
/* unit: what --dt and --every are measured in */
/* 0 keeps the integrator's own default (odhs_stepper_set_dt) */
#define CLI_DT(p, unit)                                                                                              \
    CLI_OPT_DOUBLE("--dt", p, "X", "step (heun, batched: largest step) in " unit, CLI_POSITIVE,                     \
                   .deftext = "the integrator's: 1e-3, 5e-2 batched")
/* set the step given with --dt (0: the integrator's default) */
static inline int cli_set_dt(odhs_stepper *st, double dt) { return dt > 0.0 ? odhs_stepper_set_dt(st, dt) : ODHS_OK; }
#define CLI_EVERY(p, unit) CLI_OPT_DOUBLE("--every", p, "X", "output interval in " unit, CLI_POSITIVE)
#define CLI_STRAIN(p) CLI_OPT_DOUBLE("--strain", p, "X", "total shear strain", CLI_POSITIVE)
#define CLI_TIME(p) CLI_OPT_DOUBLE("--time", p, "X", "run length in units of tau", CLI_POSITIVE)
#define CLI_SEED(p) CLI_OPT_ULONG("--seed", p, "S", "random seed", CLI_ANY)
/* the built-in scene (cli_scene): --n, --dim and --seed as three entries;
 * --phi where the scene is built at a packing fraction of its own */
#define CLI_N(p) CLI_OPT_ULONG("--n", p, "N", "built-in scene: number of particles", CLI_ATLEAST(2))
#define CLI_DIM(p) CLI_OPT_INT("--dim", p, "D", "built-in scene: dimension 2 or 3", CLI_BETWEEN(2, 3))
#define CLI_SCENE(n, dim, seed) CLI_N(n), CLI_DIM(dim), CLI_SEED(seed)
#define CLI_PHI(p) CLI_OPT_DOUBLE("--phi", p, "X", "built-in scene: packing fraction", CLI_OPEN(0, 1))
#define CLI_QUIET(p) CLI_OPT_FLAG("--quiet", p, "no progress messages on stderr (errors still)")
/* trajectories (cli_traj below); unit: what --traj-every is measured in */
#define CLI_TRAJ(p)                                                                                                  \
    CLI_OPT_STRING("--traj", p, "FILE",                                                                              \
                   "write a trajectory: extended XYZ (.xyz, for OVITO and ASE) or a LAMMPS custom dump (.dump, "     \
                   ".lammpstrj), one frame at the start and at each output at least --traj-every after the last",  \
                   CLI_ANY)
#define CLI_TRAJ_EVERY(p, unit)                                                                                      \
    CLI_OPT_DOUBLE("--traj-every", p, "X", "interval between trajectory frames in " unit, CLI_POSITIVE,             \
                   .deftext = "every output")
#define CLI_TRAJ_CONTACTS(p)                                                                                         \
    CLI_OPT_STRING("--traj-contacts", p, "FILE",                                                                     \
                   "write the contact network of each trajectory frame as a LAMMPS dump local (OVITO bonds)",       \
                   CLI_ANY)
#define CLI_CONTACTS(p)                                                                                              \
    CLI_OPT_STRING("--contacts", p, "FILE.csv", "write the final contacts as CSV: i,j,kind,force,gap", CLI_ANY)

/* ---- parser and usage -------------------------------------------------------- */

#define CLI_WIDTH 80    /* the usage is wrapped to this many columns */
#define CLI_MAX_OPTS 48 /* the longest table whose defaults cli_parse remembers */

/* x as %.15g, or as 1e-n for a power of ten that %g writes longer (1e-3,
 * not 0.001; 1e-6, not 1e-06) */
static inline void cli_format_double_(double x, char *buf, size_t len)
{
    char e[32];
    snprintf(buf, len, "%.15g", x);
    snprintf(e, sizeof e, "%.0e", x); /* 1e-03 */
    if (strncmp(e, "1e-", 3) || strtod(e, NULL) != x) return;
    const char *d = e + 3 + strspn(e + 3, "0");
    size_t n = strlen(d);
    if (n + 3 >= strlen(buf)) return;
    memcpy(buf, "1e-", 3);
    memcpy(buf + 3, d, n + 1);
}

/* the default of o as the usage shows it, or NULL for none (buf: room for a number) */
static inline const char *cli_default_(const cli_opt *o, char *buf, size_t len)
{
    if (o->kind == CLI_STRING) {
        const char *v = *(const char *const *)o->value;
        return v ? v : o->deftext;
    }
    if (o->deftext) return o->deftext;
    switch (o->kind) {
    case CLI_INT: snprintf(buf, len, "%d", *(const int *)o->value); return buf;
    case CLI_ULONG: snprintf(buf, len, "%lu", *(const unsigned long *)o->value); return buf;
    case CLI_DOUBLE: cli_format_double_(*(const double *)o->value, buf, len); return buf;
    case CLI_LIST: return o->choices[*(const int *)o->value];
    default: return NULL;
    }
}

/* text in words from column col, wrapped to CLI_WIDTH with continuation
 * lines at column indent; whole: keep it on one line if a line can hold it.
 * Returns the column reached. */
static inline int cli_words_(FILE *f, int col, int indent, const char *text, int whole)
{
    int n = (int)strlen(text), first = col == indent;
    if (whole && !first && col + 1 + n > CLI_WIDTH && indent + n <= CLI_WIDTH) {
        fprintf(f, "\n%*s", indent, "");
        col = indent;
        first = 1;
    }
    for (const char *p = text; *p;) {
        if (*p == ' ') {
            ++p;
            continue;
        }
        int w = (int)strcspn(p, " ");
        if (!first && col + 1 + w > CLI_WIDTH) {
            fprintf(f, "\n%*s", indent, "");
            col = indent;
            first = 1;
        }
        col += fprintf(f, "%s%.*s", first ? "" : " ", w, p);
        first = 0;
        p += w;
    }
    return col;
}

/* the usage; def[i]: the default of opts[i] (NULL: read the variables now) */
static inline void cli_usage_defaults_(const cli_spec *s, FILE *f, const char *const *def)
{
    if (s->mute) return;
    fprintf(f, "usage: %s %s\n", s->prog, s->synopsis ? s->synopsis : "[options]");
    int width = 18; /* "--name ARG" column: the longest one and a space */
    for (const cli_opt *o = s->opts; o->name; ++o) {
        int w = (int)strlen(o->name) + (o->arg ? 1 + (int)strlen(o->arg) : 0) + 1;
        if (w > width) width = w;
    }
    for (const cli_opt *o = s->opts; o->name; ++o) {
        char head[96], text[512], buf[32];
        snprintf(head, sizeof head, "%s%s%s", o->name, o->arg ? " " : "", o->arg ? o->arg : "");
        int col = cli_words_(f, fprintf(f, "  %-*s ", width, head), width + 3, o->help, 0);
        const char *d = def ? def[o - s->opts] : cli_default_(o, buf, sizeof buf);
        if (d && *d) {
            snprintf(text, sizeof text, "(default %s)", d);
            cli_words_(f, col, width + 3, text, 1);
        }
        fputc('\n', f);
    }
    fprintf(f, "  %-*s this message\n", width, "--help");
    if (s->footer) fputs(s->footer, f);
}

/* the defaults as the usage shows them, taken by cli_parse before it reads
 * the command line (the values the variables hold later are not defaults) */
typedef struct {
    const cli_spec *spec; /* whose defaults these are */
    const char *def[CLI_MAX_OPTS];
    char buf[CLI_MAX_OPTS][32];
} cli_defaults_;

static inline cli_defaults_ *cli_saved_(void)
{
    static cli_defaults_ saved;
    return &saved;
}

/* the usage, for a check made after cli_parse (a bad --solver ...) */
static inline void cli_usage(const cli_spec *s, FILE *f)
{
    cli_defaults_ *d = cli_saved_();
    cli_usage_defaults_(s, f, d->spec == s ? d->def : NULL);
}

static inline int cli_in_range_(const cli_opt *o, double x)
{
    return !((o->bounds & CLI_GT && !(x > o->lo)) || (o->bounds & CLI_GE && !(x >= o->lo)) ||
             (o->bounds & CLI_LT && !(x < o->hi)) || (o->bounds & CLI_LE && !(x <= o->hi)));
}

/* store the value v of option o; 0 when v is not a value o takes */
static inline int cli_set_(const cli_opt *o, const char *v)
{
    unsigned long u;
    double x;
    switch (o->kind) {
    case CLI_INT:
        if (cli_ulong(v, &u) || u > INT_MAX || !cli_in_range_(o, (double)u)) return 0;
        *(int *)o->value = (int)u;
        return 1;
    case CLI_ULONG:
        if (cli_ulong(v, &u) || !cli_in_range_(o, (double)u)) return 0;
        *(unsigned long *)o->value = u;
        return 1;
    case CLI_DOUBLE:
        if (cli_double(v, &x) || !cli_in_range_(o, x)) return 0;
        *(double *)o->value = x;
        return 1;
    case CLI_STRING: *(const char **)o->value = v; return 1;
    case CLI_LIST:
        for (int k = 0; o->choices[k]; ++k)
            if (!strcmp(v, o->choices[k])) {
                *(int *)o->value = k;
                return 1;
            }
        return 0;
    default: return 0;
    }
}

/* Read the command line into the table's variables. Returns CLI_GO, or the
 * exit status: 0 after --help, 2 after a bad option (message and usage on
 * stderr). */
static inline int cli_parse(const cli_spec *s, int argc, char **argv)
{
    size_t n = 0;
    while (s->opts[n].name) ++n;
    cli_defaults_ *d = cli_saved_();
    d->spec = n <= CLI_MAX_OPTS ? s : NULL;
    for (size_t i = 0; d->spec && i < n; ++i) d->def[i] = cli_default_(&s->opts[i], d->buf[i], sizeof d->buf[i]);
    for (int a = 1; a < argc; ++a) {
        const char *o = argv[a];
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
            cli_usage(s, stdout);
            return 0;
        }
        const cli_opt *opt = s->opts;
        while (opt->name && strcmp(opt->name, o)) ++opt;
        if (opt->name && opt->kind == CLI_FLAG) {
            *(int *)opt->value = 1;
            continue;
        }
        int bad = 1;
        if (a + 1 >= argc) {
            if (!s->mute) fprintf(stderr, "%s: unknown option or missing value: %s\n", s->prog, o);
        } else if (!opt->name) {
            if (!s->mute) fprintf(stderr, "%s: unknown option %s\n", s->prog, o);
        } else if (!cli_set_(opt, argv[++a])) {
            if (!s->mute) fprintf(stderr, "%s: bad value for %s: %s\n", s->prog, o, argv[a]);
        } else {
            bad = 0;
        }
        if (bad) {
            cli_usage(s, stderr);
            return 2;
        }
    }
    return CLI_GO;
}

/* ---- the scene, the solver and the files --------------------------------------- */

/* The examples' built-in scene: 50:50 bidisperse radii 0.5/0.7 with 3%
 * polydispersity, placed at random at phi = 0.45 (2D) or 0.30 (3D), or at
 * phi_max if that is lower. Returns ODHS_OK or an error (the message is in
 * the system handle when *out is not NULL). */
static inline int cli_scene(int dim, unsigned long n, unsigned long seed, double phi_max, odhs_system **out)
{
    double phi0 = dim == 2 ? 0.45 : 0.30;
    if (phi_max < phi0) phi0 = phi_max;
    int rc = odhs_system_create(dim, n, out);
    if (rc) return rc;
    if ((rc = odhs_system_set_radii_bidisperse(*out, 0.5, 1.4, 0.03, seed))) return rc;
    return odhs_system_place_random(*out, phi0, seed + 1);
}

/* the solver of that name; 0, or 2 (a bad --solver) with a message */
static inline int cli_solver(const char *prog, const char *name, odhs_solver **out)
{
    int rc = odhs_solver_create_by_name(name, out);
    if (!rc) return 0;
    /* the library's message names the solvers this build has */
    fprintf(stderr, "%s: solver %s: %s\n", prog, name, odhs_last_error()[0] ? odhs_last_error() : odhs_strerror(rc));
    return 2;
}

/* The built-in scene compressed to phi (shear_flow, lammps_coupling): the
 * random placement of cli_scene, then event-driven isotropic compression to
 * phi with solver and a drift correction, so that a run starts from contacts
 * at exact touching. 0, or 1 with a message. */
static inline int cli_compressed_scene(const char *prog, int dim, unsigned long n, double phi, unsigned long seed,
                                       odhs_solver *solver, int quiet, odhs_system **out)
{
    odhs_system *sys = NULL;
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    double phi0 = dim == 2 ? 0.45 : 0.3;
    if (phi < phi0) phi0 = phi;
    int rc = cli_scene(dim, n, seed, phi, &sys);
    if (rc) {
        fprintf(stderr, "%s: %s\n", prog, sys ? odhs_system_errmsg(sys) : odhs_strerror(rc));
        odhs_system_destroy(sys);
        return 1;
    }
    if (phi > phi0) {
        if ((rc = odhs_driver_create(&drv)) || (rc = odhs_driver_set_compression_rate(drv, 1.0)) ||
            (rc = odhs_stepper_create(sys, drv, solver, &st)) || (rc = odhs_stepper_set_dt(st, 1e-3))) {
            fprintf(stderr, "%s: setting up the compression: %s (%s)\n", prog, odhs_strerror(rc), odhs_last_error());
            rc = 1;
            goto done;
        }
        if (!quiet) fprintf(stderr, "%s: compressing from phi = %.3f to %.3f\n", prog, phi0, phi);
        rc = odhs_stepper_run_until_packing_fraction(st, phi);
        if (rc) {
            fprintf(stderr, "%s: compression stopped: %s (%s)\n", prog, odhs_strerror(rc), odhs_stepper_errmsg(st));
            rc = 1;
            goto done;
        }
        /* contacts back to exact touching, so the run starts from them */
        if (odhs_stepper_correct(st) < 0) {
            fprintf(stderr, "%s: %s\n", prog, odhs_stepper_errmsg(st));
            rc = 1;
            goto done;
        }
    }
    rc = 0;
done:
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    if (rc) odhs_system_destroy(sys);
    else *out = sys;
    return rc;
}

/* whether path names a LAMMPS data file: it ends in .data, .lmp or .lammps,
 * or (another name) its first line is not a particle count */
static inline int cli_is_lammps_data_(const char *path)
{
    static const char *const ends[] = {".data", ".lmp", ".lammps"};
    size_t n = strlen(path);
    for (size_t k = 0; k < sizeof ends / sizeof ends[0]; ++k) {
        size_t m = strlen(ends[k]);
        if (n > m && !strcmp(path + n - m, ends[k])) return 1;
    }
    if (n > 4 && (!strcmp(path + n - 4, ".xyz") || (n > 7 && !strcmp(path + n - 7, ".extxyz")))) return 0;
    FILE *f = fopen(path, "r");
    char line[64] = "";
    if (!f) return 0; /* the reader reports it */
    int got = fgets(line, sizeof line, f) != NULL;
    fclose(f);
    unsigned long v;
    line[strcspn(line, "\r\n")] = 0;
    return got && cli_ulong(line + strspn(line, " \t"), &v) != 0;
}

/* the configuration in the file (--in): extended XYZ, or a LAMMPS data file
 * (atom_style sphere); 0, or 1 (unreadable) with a message */
static inline int cli_read_xyz(const char *prog, const char *path, odhs_system **out)
{
    char err[512];
    int lammps = cli_is_lammps_data_(path);
    if (!(lammps ? odhs_lammps_data_read(path, out, err, sizeof err) : odhs_xyz_read(path, out, err, sizeof err)))
        return 0;
    fprintf(stderr, "%s: cannot read %s: %s\n", prog, path, err);
    return 1;
}

/* --out: extended XYZ, or a LAMMPS data file for the names of
 * cli_is_lammps_data_'s list; 0, or 1 with a message */
static inline int cli_write_config(const char *prog, const odhs_system *sys, const char *path)
{
    size_t n = strlen(path);
    int lammps = (n > 5 && !strcmp(path + n - 5, ".data")) || (n > 4 && !strcmp(path + n - 4, ".lmp")) ||
                 (n > 7 && !strcmp(path + n - 7, ".lammps"));
    if (!(lammps ? odhs_lammps_data_write(sys, path) : odhs_xyz_write(sys, path))) return 0;
    fprintf(stderr, "%s: cannot write %s: %s\n", prog, path, odhs_system_errmsg(sys));
    return 1;
}

/* the configuration of --in when there is one, else the built-in scene
 * (cli_scene; *out NULL on entry); 0, or 1 with a message */
static inline int cli_start(const char *prog, const char *in, int dim, unsigned long n, unsigned long seed,
                            double phi_max, odhs_system **out)
{
    if (in) return cli_read_xyz(prog, in, out);
    int rc = cli_scene(dim, n, seed, phi_max, out);
    if (!rc) return 0;
    fprintf(stderr, "%s: building the scene: %s\n", prog, *out ? odhs_system_errmsg(*out) : odhs_strerror(rc));
    return 1;
}

/* the --series file opened with its header line (then units, when not NULL,
 * as a comment line "# units: ..."; numpy.genfromtxt(names=True) skips it,
 * pandas.read_csv wants comment="#"), or *out = NULL without a path; 0, or
 * 1 (cannot write) with a message */
static inline int cli_series_units(const char *prog, const char *path, const char *columns, const char *units,
                                   FILE **out)
{
    *out = NULL;
    if (!path) return 0;
    if (!(*out = fopen(path, "w"))) {
        fprintf(stderr, "%s: cannot write %s: %s\n", prog, path, strerror(errno));
        return 1;
    }
    fprintf(*out, "%s\n", columns);
    if (units) fprintf(*out, "# units: %s\n", units);
    return 0;
}

static inline int cli_series(const char *prog, const char *path, const char *columns, FILE **out)
{
    return cli_series_units(prog, path, columns, NULL, out);
}

/* ---- progress on stderr ------------------------------------------------------- */

/* One updating line (carriage return) with the elapsed time, the rate (of
 * the run's own unit: strain, time, ...) and the estimated time left when
 * stderr is a terminal; otherwise plain lines, at most one every
 * CLI_PROGRESS_LOG seconds and one at the end; nothing with --quiet. */
#define CLI_PROGRESS_LOG 10.0

typedef struct {
    const char *prog;
    int quiet, tty, shown; /* shown: a line is on the terminal, not ended */
    double t0, last;       /* wall-clock seconds at the start, at the last line */
    char text[256];
} cli_progress;

static inline double cli_now_(void)
{
    struct timespec ts;
    timespec_get(&ts, TIME_UTC);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static inline void cli_progress_init(cli_progress *p, const char *prog, int quiet)
{
    memset(p, 0, sizeof *p);
    p->prog = prog;
    p->quiet = quiet;
    p->tty = isatty(fileno(stderr));
    p->t0 = p->last = cli_now_();
}

/* done of total (in the run's own unit) and a description; final: the last
 * call (always printed) */
static inline void cli_progress_show(cli_progress *p, double done, double total, int final, const char *fmt, ...)
{
    if (p->quiet) return;
    double now = cli_now_(), el = now - p->t0;
    if (!p->tty && !final && now - p->last < CLI_PROGRESS_LOG) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->text, sizeof p->text, fmt, ap);
    va_end(ap);
    char eta[64] = "";
    if (!final && done > 0.0 && total > done && el > 0.0)
        snprintf(eta, sizeof eta, ", %.3g/s, %.0f s left", done / el, el * (total - done) / done);
    fprintf(stderr, "%s%s: %s, %.1f s%s%s", p->tty ? "\r" : "", p->prog, p->text, el, eta,
            p->tty && !final ? "\033[K" : "\n");
    if (p->tty && final) p->shown = 0;
    else p->shown = p->tty;
    p->last = now;
}

/* end an updating line before other output on stderr */
static inline void cli_progress_break(cli_progress *p)
{
    if (p->shown) fputc('\n', stderr);
    p->shown = 0;
}

/* ---- trajectories (--traj, --traj-every, --traj-contacts) ---------------------------- */

/* Frames are written at the example's outputs (never at extra stopping
 * points, so a trajectory never changes the run): at the start and at each
 * output at least `every` after the last frame (every <= 0: each output). */
typedef struct {
    const char *prog, *path, *cpath;
    odhs_traj *tr, *contacts;
    double every, last;
    int started;
} cli_traj;

/* open the files named (either may be NULL); 0, or 2 (a --traj name of no
 * known format) or 1 (cannot write) with a message */
static inline int cli_traj_open(cli_traj *t, const char *prog, const char *path, const char *contacts, double every)
{
    memset(t, 0, sizeof *t);
    t->prog = prog;
    t->path = path;
    t->cpath = contacts;
    t->every = every;
    char err[512];
    int format = ODHS_TRAJ_XYZ;
    if (path && odhs_traj_format_for(path, &format)) {
        fprintf(stderr, "%s: --traj %s: name the file .xyz or .extxyz (extended XYZ) or .dump or .lammpstrj (LAMMPS "
                        "dump)\n", prog, path);
        return 2;
    }
    if ((path && odhs_traj_open(path, format, &t->tr, err, sizeof err)) ||
        (contacts && odhs_traj_open(contacts, ODHS_TRAJ_LAMMPS_LOCAL, &t->contacts, err, sizeof err))) {
        fprintf(stderr, "%s: %s\n", prog, err);
        odhs_traj_close(t->tr);
        t->tr = NULL;
        return 1;
    }
    return 0;
}

/* at an output where the run's clock (strain, time, ...) reads x: a frame if
 * one is due; 0, or 1 with a message */
static inline int cli_traj_output(cli_traj *t, const odhs_system *sys, const odhs_stepper *st, double x)
{
    if (!t->tr && !t->contacts) return 0;
    if (t->started && !(x - t->last >= t->every * (1.0 - 1e-9))) return 0;
    t->started = 1;
    t->last = x;
    if (t->tr && odhs_traj_write(t->tr, sys, st)) {
        fprintf(stderr, "%s: %s: %s\n", t->prog, t->path, odhs_traj_errmsg(t->tr));
        return 1;
    }
    if (t->contacts && st && odhs_traj_write(t->contacts, sys, st)) {
        fprintf(stderr, "%s: %s: %s\n", t->prog, t->cpath, odhs_traj_errmsg(t->contacts));
        return 1;
    }
    return 0;
}

/* close the files; 0, or 1 with a message */
static inline int cli_traj_close(cli_traj *t)
{
    int bad = 0;
    if (odhs_traj_close(t->tr)) {
        fprintf(stderr, "%s: error writing %s\n", t->prog, t->path);
        bad = 1;
    }
    if (odhs_traj_close(t->contacts)) {
        fprintf(stderr, "%s: error writing %s\n", t->prog, t->cpath);
        bad = 1;
    }
    t->tr = t->contacts = NULL;
    return bad;
}

/* ---- --plot: a series against its first column --------------------------------- */

#define CLI_PLOT(p)                                                                                                  \
    CLI_OPT_STRING("--plot", p, "FILE.svg", "plot the series: each column against the first, one panel each",     \
                   CLI_ANY)
#define CLI_PLOT_MAX 8 /* panels */

typedef struct {
    pl_plot panel[CLI_PLOT_MAX];
    int n, on;
} cli_plot;

/* panels for the CSV header columns (the first is the x axis); nothing
 * without a path */
static inline void cli_plot_init(cli_plot *p, const char *path, const char *title, const char *columns)
{
    memset(p, 0, sizeof *p);
    if (!path) return;
    p->on = 1;
    char names[CLI_PLOT_MAX + 1][48];
    int k = 0;
    for (const char *c = columns; *c && k <= CLI_PLOT_MAX; ++k) {
        size_t w = strcspn(c, ",");
        snprintf(names[k], sizeof names[k], "%.*s", (int)(w < 47 ? w : 47), c);
        c += w + (c[w] == ',');
    }
    for (int j = 1; j < k; ++j) {
        pl_init(&p->panel[p->n], j == 1 ? title : "", names[0], names[j], 0, 0);
        pl_series_add(&p->panel[p->n], names[j], j - 1, 0, 0);
        p->n++;
    }
}

/* one row: v[0] the x value, v[1..] the columns */
static inline void cli_plot_row(cli_plot *p, const double *v)
{
    for (int j = 0; p->on && j < p->n; ++j) pl_point(&p->panel[j], 0, v[0], v[j + 1]);
}

/* write the picture and free the panels; 0, or 1 with a message */
static inline int cli_plot_write(cli_plot *p, const char *prog, const char *path)
{
    if (!p->on) return 0;
    const pl_plot *panels[CLI_PLOT_MAX];
    for (int j = 0; j < p->n; ++j) panels[j] = &p->panel[j];
    int bad = pl_write_svg_panels(panels, p->n, path);
    for (int j = 0; j < p->n; ++j) pl_free(&p->panel[j]);
    p->on = 0;
    if (bad) fprintf(stderr, "%s: cannot write %s\n", prog, path);
    return bad != 0;
}

#endif /* ODHS_EXAMPLES_CLI_H */
