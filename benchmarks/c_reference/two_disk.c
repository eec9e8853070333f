/* Reference C loop of the two-disk billiard: the algorithm and the output of
 * kicktimes.billiard.two_particle.simulate_two_kernel (mirror and elastic rules, no / uniform
 * / paper sampling, boundary log, disk-disk times, samples of one disk), written as a C
 * programmer would: plain doubles, fresh malloc'd output arrays per run, grown by doubling
 * like the kernel's. benchmarks/bench_simulators.py builds it with `cc -O2 -shared -fPIC`,
 * checks that its output equals the kernel's and times it against simulate_two_particle.
 *
 * The grazing constants come from the Python module (-DSIN_GRAZE=... etc.) so that both
 * use the same bits. No -ffast-math and no FMA (baseline x86-64): IEEE operations in
 * source order, as numba compiles them.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifndef SIN_GRAZE
#error "compile with -DSIN_GRAZE=... -DCOS_GRAZE=... -DGRAZE_THRESHOLD=..."
#endif

enum { DONE = 0, FULL = 1, STALLED = 2, OVER_BUDGET = 3 };
#define STALL_EVENTS 10000

typedef struct {
    double *pp, *bt, *bx, *by, *bs, *stimes, *samples;
    int8_t *bp;
    int64_t n_pp, n_b, ns;
    double t_end;
    double st[11];
    int status;
} two_disk_out;

static double boundary_hit_time(double x, double y, double vx, double vy, double rho) {
    double vv = vx * vx + vy * vy;
    if (vv == 0.0) return INFINITY;
    double b = x * vx + y * vy;
    double c = rho * rho - (x * x + y * y);
    double disc = b * b + vv * c;
    if (disc < 0.0) disc = 0.0;
    double t = b > 0.0 ? c / (b + sqrt(disc)) : (-b + sqrt(disc)) / vv;
    return t < 0.0 ? 0.0 : t;
}

static double pair_hit_time(double dx, double dy, double wx, double wy, double sigma) {
    double b = dx * wx + dy * wy;
    if (b >= 0.0) return INFINITY;
    double ww = wx * wx + wy * wy;
    double c = dx * dx + dy * dy - sigma * sigma;
    double disc = b * b - ww * c;
    if (disc <= 0.0) return INFINITY;
    double t = c / (-b + sqrt(disc));
    return t < 0.0 ? 0.0 : t;
}

static void *grow(void *a, int64_t n, int64_t limit, size_t size) {
    int64_t m = 2 * n + 16;
    if (m > limit) m = limit;
    void *out = malloc((size_t)m * size);
    memcpy(out, a, (size_t)n * size);
    free(a);
    return out;
}

static int stalled(const double *times, int64_t n, double stall_dt) {
    if (n < STALL_EVENTS) return 0;
    return times[n - 1] - times[n - STALL_EVENTS] < STALL_EVENTS * stall_dt;
}

/* st0 = the kernel's initial state [0, x0, y0, vx0, vy0, x1, y1, vx1, vy1, 0, e0]
 * (e0 = the kinetic energy as the Python layer sums it); mode 0 none, 1 uniform, 2 paper. */
int two_disk(const double *st0, double rho, double sigma, int rule, double t_max, int mode,
             int64_t n_steps, double tau, int track, int64_t pp_cap, int64_t b_cap,
             int64_t max_events, double stall_dt, two_disk_out *out) {
    double t = 0.0, c = 0.0;
    double x0 = st0[1], y0 = st0[2], vx0 = st0[3], vy0 = st0[4];
    double x1 = st0[5], y1 = st0[6], vx1 = st0[7], vy1 = st0[8];
    double e0 = st0[10];
    double tb0 = boundary_hit_time(x0, y0, vx0, vy0, rho);
    double tb1 = boundary_hit_time(x1, y1, vx1, vy1, rho);
    double tpp = pair_hit_time(x0 - x1, y0 - y1, vx0 - vx1, vy0 - vy1, sigma);
    if (pp_cap > max_events + 1) pp_cap = max_events + 1;
    if (b_cap > max_events + 1) b_cap = max_events + 1;
    double *pp = malloc((size_t)pp_cap * sizeof(double));
    double *bt = malloc((size_t)b_cap * sizeof(double));
    int8_t *bp = malloc((size_t)b_cap);
    double *bx = malloc((size_t)b_cap * sizeof(double));
    double *by = malloc((size_t)b_cap * sizeof(double));
    double *bs = malloc((size_t)b_cap * sizeof(double));
    int64_t ns = mode > 0 ? n_steps + 1 : 0;
    double *stimes = malloc((size_t)(ns > 0 ? ns : 1) * sizeof(double));
    double *samples = malloc((size_t)(ns > 0 ? 2 * ns : 1) * sizeof(double));
    int64_t n_pp = 0, n_b = 0, k = 0;
    double ns_next = 0.0;
    double t_end = mode < 2 ? t_max : INFINITY;
    int status;
    for (;;) {
        status = FULL;
        for (;;) {
            int ke = 0;
            double dte = tb0;
            if (tb1 < dte) { ke = 1; dte = tb1; }
            if (tpp < dte) { ke = 2; dte = tpp; }
            while (k < ns && ns_next - t < dte) {
                double ds = ns_next - t;
                stimes[k] = ns_next;
                if (track == 0) {
                    samples[2 * k] = x0 + vx0 * ds;
                    samples[2 * k + 1] = y0 + vy0 * ds;
                } else {
                    samples[2 * k] = x1 + vx1 * ds;
                    samples[2 * k + 1] = y1 + vy1 * ds;
                }
                k++;
                ns_next = mode == 1 ? (double)k * tau : ns_next + tau;
            }
            if ((mode == 2 && k >= ns) || t + dte > t_end) { status = DONE; break; }
            if ((ke == 2 && n_pp >= pp_cap) || (ke < 2 && n_b >= b_cap)) break;
            /* free flight to the event; Kahan-compensated clock, relative event times */
            double dt = dte;
            x0 += vx0 * dt; y0 += vy0 * dt; x1 += vx1 * dt; y1 += vy1 * dt;
            tb0 -= dt; tb1 -= dt; tpp -= dt;
            double yk = dt - c, tn = t + yk;
            c = (tn - t) - yk;
            t = tn;
            double sin_theta = 0.0;
            if (ke < 2) {
                double x = ke ? x1 : x0, y = ke ? y1 : y0;
                double vx = ke ? vx1 : vx0, vy = ke ? vy1 : vy0;
                double scale = 1.5 - 0.5 * (x * x + y * y) / (rho * rho);
                x *= scale;
                y *= scale;
                double vv = vx * vx + vy * vy, sp;
                if (rule == 0) {
                    double sv = 1.5 - 0.5 * vv;
                    vx *= sv;
                    vy *= sv;
                    vv = 1.0;
                    sp = 1.0;
                    sin_theta = (x * vy - y * vx) / rho;
                } else {
                    sp = sqrt(vv);
                    sin_theta = (x * vy - y * vx) / (rho * sp);
                }
                double xv = x * vx + y * vy;
                double gz = GRAZE_THRESHOLD * rho * sp;
                double tb;
                if (xv > gz) {
                    double nx = x / rho, ny = y / rho;
                    double p = 2.0 * (vx * nx + vy * ny);
                    vx = vx - p * nx;
                    vy = vy - p * ny;
                    tb = 2.0 * xv / vv;
                } else if (xv >= -gz) {
                    double nx = x / rho, ny = y / rho;
                    double s = x * vy - y * vx >= 0.0 ? 1.0 : -1.0;
                    double gx = sp * (-SIN_GRAZE * nx - s * COS_GRAZE * ny);
                    double gy = sp * (-SIN_GRAZE * ny + s * COS_GRAZE * nx);
                    vx = gx;
                    vy = gy;
                    tb = 2.0 * rho * SIN_GRAZE / sp;
                } else {
                    tb = boundary_hit_time(x, y, vx, vy, rho);
                }
                if (ke) { x1 = x; y1 = y; vx1 = vx; vy1 = vy; tb1 = tb; }
                else { x0 = x; y0 = y; vx0 = vx; vy0 = vy; tb0 = tb; }
            } else {
                double dx = x0 - x1, dy = y0 - y1;
                double dd = sqrt(dx * dx + dy * dy);
                double nx = dx / dd, ny = dy / dd;
                double a, b, cc, d;
                if (rule == 0) {
                    double p = 2.0 * (vx0 * nx + vy0 * ny);
                    a = vx0 - p * nx;
                    b = vy0 - p * ny;
                    p = 2.0 * (vx1 * nx + vy1 * ny);
                    cc = vx1 - p * nx;
                    d = vy1 - p * ny;
                    double s1 = 1.5 - 0.5 * (a * a + b * b);
                    double s2 = 1.5 - 0.5 * (cc * cc + d * d);
                    a *= s1; b *= s1; cc *= s2; d *= s2;
                } else {
                    double p = (vx0 - vx1) * nx + (vy0 - vy1) * ny;
                    a = vx0 - p * nx;
                    b = vy0 - p * ny;
                    cc = vx1 + p * nx;
                    d = vy1 + p * ny;
                }
                vx0 = a; vy0 = b; vx1 = cc; vy1 = d;
                tb0 = boundary_hit_time(x0, y0, a, b, rho);
                tb1 = boundary_hit_time(x1, y1, cc, d, rho);
            }
            if (rule != 0) {
                double e = vx0 * vx0 + vy0 * vy0;
                e += vx1 * vx1;
                e += vy1 * vy1;
                double f = 1.5 - 0.5 * e / e0;
                vx0 *= f; vy0 *= f; vx1 *= f; vy1 *= f;
            }
            tpp = pair_hit_time(x0 - x1, y0 - y1, vx0 - vx1, vy0 - vy1, sigma);
            if (ke == 2) {
                pp[n_pp++] = t;
            } else {
                bt[n_b] = t;
                bp[n_b] = (int8_t)ke;
                bx[n_b] = ke ? x1 : x0;
                by[n_b] = ke ? y1 : y0;
                bs[n_b] = sin_theta;
                n_b++;
            }
            if (mode == 2 && k < ns) {
                stimes[k] = t;
                samples[2 * k] = track ? x1 : x0;
                samples[2 * k + 1] = track ? y1 : y0;
                k++;
                ns_next = t + tau;
            }
        }
        if (stalled(pp, n_pp, stall_dt) || stalled(bt, n_b, stall_dt)) { status = STALLED; break; }
        if (status != FULL) break;
        int64_t room = max_events - n_pp - n_b;
        if (room <= 0) { status = OVER_BUDGET; break; }
        if (n_pp >= pp_cap) {
            int64_t limit = pp_cap + room;
            pp = grow(pp, n_pp, limit, sizeof(double));
            pp_cap = 2 * pp_cap + 16 < limit ? 2 * pp_cap + 16 : limit;
        }
        if (n_b >= b_cap) {
            int64_t limit = b_cap + room;
            int64_t m = 2 * b_cap + 16 < limit ? 2 * b_cap + 16 : limit;
            bt = grow(bt, n_b, limit, sizeof(double));
            bp = grow(bp, n_b, limit, 1);
            bx = grow(bx, n_b, limit, sizeof(double));
            by = grow(by, n_b, limit, sizeof(double));
            bs = grow(bs, n_b, limit, sizeof(double));
            b_cap = m;
        }
    }
    if (status == DONE) {
        if (mode == 2) t_end = stimes[ns - 1];
        double dt = t_end - t;
        x0 += vx0 * dt; y0 += vy0 * dt; x1 += vx1 * dt; y1 += vy1 * dt;
        t = t_end;
        c = 0.0;
    }
    out->pp = pp; out->bt = bt; out->bp = bp; out->bx = bx; out->by = by; out->bs = bs;
    out->stimes = stimes; out->samples = samples;
    out->n_pp = n_pp; out->n_b = n_b; out->ns = ns; out->t_end = t_end; out->status = status;
    double st[11] = {t, x0, y0, vx0, vy0, x1, y1, vx1, vy1, c, e0};
    memcpy(out->st, st, sizeof st);
    return status;
}

void two_disk_free(two_disk_out *out) {
    free(out->pp); free(out->bt); free(out->bp); free(out->bx); free(out->by); free(out->bs);
    free(out->stimes); free(out->samples);
}

/* The timed loop: n_ics runs one after the other, each with fresh output arrays (freed
 * after the run, as a caller that reduces each run and drops it would); returns the total
 * number of events, so that the work cannot be optimised away. */
int64_t two_disk_many(const double *st0s, int64_t n_ics, double rho, double sigma, int rule,
                      double t_max, int mode, int64_t n_steps, double tau, int track,
                      const int64_t *pp_cap, const int64_t *b_cap, const int64_t *max_events,
                      const double *stall_dt) {
    int64_t events = 0;
    two_disk_out out;
    for (int64_t i = 0; i < n_ics; i++) {
        two_disk(st0s + 11 * i, rho, sigma, rule, t_max, mode, n_steps, tau, track, pp_cap[i],
                 b_cap[i], max_events[i], stall_dt[i], &out);
        events += out.n_pp + out.n_b;
        two_disk_free(&out);
    }
    return events;
}
