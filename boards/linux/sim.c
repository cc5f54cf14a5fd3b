/*
 * sim.c - the simulated physics; see sim.h.
 */
#include "sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

bool sim_value(const char *str, double lim, int32_t *out)
{
    char *end;
    double x = strtod(str, &end);
    if (end == str || *end != '\0' || !isfinite(x) || fabs(x) > lim) {
        return false;
    }
    *out = (int32_t)lround(x * 1000.0);
    return true;
}

int sim_input_index(const product_t *p, const char *name, size_t len)
{
    for (int i = 0; i < (int)PRODUCT_MAX_INPUTS && p->inputs[i].name != NULL; i++) {
        if (strlen(p->inputs[i].name) == len && strncmp(p->inputs[i].name, name, len) == 0) {
            return i;
        }
    }
    return -1;
}

void sim_init(sim_t *s, const product_t *p)
{
    memset(s, 0, sizeof(*s));
    s->prod = p;
    s->seed = SIM_SEED_DEFAULT;
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        s->values[i] = p->inputs[i].initial;
        s->motion[i].kind = SIM_HOLD;
        s->motion[i].from = p->inputs[i].initial;
        s->replay.col[i] = -1;
    }
}

void sim_seed(sim_t *s, uint64_t seed)
{
    s->seed = seed;
}

/* splitmix64's output function: a well-mixed 64-bit value of x. */
static uint64_t mix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15u;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9u;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBu;
    return x ^ (x >> 31);
}

/* A uniform number in (0, 1] from 64 random bits. */
static double unit_interval(uint64_t r)
{
    return (double)((r >> 11) + 1u) * (1.0 / 9007199254740992.0);
}

/*
 * Standard normal value of input i in simulated millisecond ms: counter-
 * based (a function of seed, i and ms only), Box-Muller on two uniforms.
 */
static double gauss(uint64_t seed, unsigned i, uint64_t ms)
{
    uint64_t key = mix64(seed) ^ mix64(ms * PRODUCT_MAX_INPUTS + i);
    double u1 = unit_interval(mix64(key));
    double u2 = unit_interval(mix64(key ^ 0xD1B54A32D192ED03u));
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* num / den rounded to nearest (halves away from zero), den > 0. */
static int64_t div_round(int64_t num, int64_t den)
{
    return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

/* a * b / c rounded (b >= 0, c > 0). Exact in 64 bits while a * b fits;
 * beyond (the GSH-A's +-100 000 mm ramped over a day: 2e8 x 8.6e10), in
 * double, whose error there is far below a thousandth. */
static int64_t scale_round(int64_t a, int64_t b, int64_t c)
{
    int64_t mag = a >= 0 ? a : -a;
    if (b == 0 || mag <= INT64_MAX / b) {
        return div_round(a * b, c);
    }
    return (int64_t)llround((double)a * (double)b / (double)c);
}

/* The motion's value of input i at simulated time t (noise left out). */
static int32_t motion_value(const sim_t *s, unsigned i, uint64_t t)
{
    const sim_motion_t *m = &s->motion[i];
    uint64_t el = t - m->start_us; /* commands start at the last step: t >= start */
    switch (m->kind) {
    case SIM_RAMP:
        if (el >= m->dur_us) {
            return m->to;
        }
        return m->from +
               (int32_t)scale_round((int64_t)m->to - m->from, (int64_t)el, (int64_t)m->dur_us);
    case SIM_SINE: {
        double phase = (double)(el % m->dur_us) / (double)m->dur_us;
        return m->from + (int32_t)lround((double)m->amp * sin(6.283185307179586 * phase));
    }
    case SIM_REPLAY: {
        const sim_replay_t *r = &s->replay;
        int c = r->col[i];
        if (el < r->t_us[0]) {
            return m->from;
        }
        uint32_t k = 1;
        while (k < r->rows && r->t_us[k] <= el) {
            k++;
        }
        if (k >= r->rows) {
            return r->v[r->rows - 1u][c];
        }
        int64_t v0 = r->v[k - 1u][c];
        int64_t dt = (int64_t)(r->t_us[k] - r->t_us[k - 1u]);
        return (int32_t)(v0 + scale_round(r->v[k][c] - v0, (int64_t)(el - r->t_us[k - 1u]), dt));
    }
    case SIM_HOLD:
    default:
        return m->from;
    }
}

/* values[] at the simulated time: motion + noise, saturated at +-limit. */
static void compute(sim_t *s)
{
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && s->prod->inputs[i].name != NULL; i++) {
        int64_t v = motion_value(s, i, s->t_us);
        if (s->motion[i].sd != 0) {
            v += lround((double)s->motion[i].sd * gauss(s->seed, i, s->t_us / 1000u));
        }
        int64_t lim = (int64_t)s->prod->inputs[i].limit * 1000;
        v = v > lim ? lim : v < -lim ? -lim : v;
        s->values[i] = (int32_t)v;
    }
}

void sim_step(sim_t *s, uint32_t now_us)
{
    if (s->stepped) {
        s->t_us += (uint32_t)(now_us - s->last_us);
    }
    s->stepped = true;
    s->last_us = now_us;
    compute(s);
}

/* A new motion of input i from now on (its noise kept). */
static void start_motion(sim_t *s, unsigned i, sim_kind_t kind, int32_t from)
{
    sim_motion_t *m = &s->motion[i];
    m->kind = kind;
    m->from = from;
    m->start_us = s->t_us;
    if (s->replay.col[i] >= 0 && kind != SIM_REPLAY) {
        s->replay.col[i] = -1; /* off the replay */
    }
}

int32_t sim_motion_now(const sim_t *s, unsigned i)
{
    return motion_value(s, i, s->t_us);
}

void sim_hold(sim_t *s, unsigned i, int32_t v)
{
    start_motion(s, i, SIM_HOLD, v);
    compute(s);
}

void sim_ramp(sim_t *s, unsigned i, int32_t to, uint64_t dur_us)
{
    start_motion(s, i, SIM_RAMP, motion_value(s, i, s->t_us));
    s->motion[i].to = to;
    s->motion[i].dur_us = dur_us;
    compute(s);
}

void sim_sine(sim_t *s, unsigned i, int32_t amp, uint64_t period_us)
{
    start_motion(s, i, SIM_SINE, motion_value(s, i, s->t_us));
    s->motion[i].amp = amp;
    s->motion[i].dur_us = period_us;
    compute(s);
}

void sim_noise(sim_t *s, unsigned i, int32_t sd)
{
    s->motion[i].sd = sd;
    compute(s);
}

void sim_fault(sim_t *s, unsigned f, bool on)
{
    if (on) {
        s->faults |= 1u << f;
    } else {
        s->faults &= ~(1u << f);
    }
}

void sim_replay_start(sim_t *s, const sim_replay_t *table)
{
    int32_t now[PRODUCT_MAX_INPUTS];
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        now[i] = motion_value(s, i, s->t_us);
    }
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        if (s->motion[i].kind == SIM_REPLAY) {
            start_motion(s, i, SIM_HOLD, now[i]); /* the former replay stops */
        }
    }
    if (table != &s->replay) {
        s->replay = *table;
    }
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        if (s->replay.col[i] >= 0) {
            start_motion(s, i, SIM_REPLAY, now[i]);
        }
    }
    compute(s);
}
