/*
 * sim.h - the simulated physics of one product instance: the true value of
 * each input over time and the forced faults. What the line language
 * (cmd.h) asks for arrives here checked; nothing here parses a command.
 *
 * Motion. Each input has one motion (hold, ramp, sine or replay: what
 * sim_hold, sim_ramp, sim_sine or sim_replay_start last gave it) and, on
 * top, its noise: a new motion of an input replaces its former one (a
 * ramp or sine starts from the motion's value at that time, noise left
 * out) and keeps its noise; noise changes only with sim_noise.
 * Limits (product_t inputs[].limit) are the caller's to check for what it
 * asks outright (cmd.c does); noise can carry a value past them, and the
 * sum is saturated at +-limit.
 *
 * Replay: one runs at a time; a new one stops the former (inputs it drove
 * hold their value), and a new motion takes an input off the replay. The
 * named inputs hold their value until the table's first row's time, are
 * interpolated linearly between rows and hold the last row's values
 * after it.
 *
 * Time and determinism. The board passes its clock (microseconds, may
 * wrap) to sim_step() before each sample; the simulated time is the sum of
 * its steps (64 bits, from 0 at the first step). A change takes effect at
 * the time of the last sim_step(). Every value is a function of the
 * changes, the times they were made and the seed: ramp and replay are
 * integer arithmetic; noise is a counter-based generator (splitmix64 of
 * the seed, the input and the simulated millisecond) through Box-Muller,
 * so it does not depend on how often sim_step() is called; a new value
 * each simulated millisecond. Values are int32 thousandths of the unit.
 */
#ifndef LINUX_SIM_H
#define LINUX_SIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "product.h"
#include "replay_csv.h"

/* Longest ramp, sine period (seconds): one day. */
#define SIM_DURATION_MAX_S 86400u

/* Seed when none is given (--seed). */
#define SIM_SEED_DEFAULT 1u

typedef enum sim_kind { SIM_HOLD, SIM_RAMP, SIM_SINE, SIM_REPLAY } sim_kind_t;

typedef struct sim_motion {
    sim_kind_t kind;
    int32_t from;      /* held value, ramp start, sine centre (thousandths) */
    int32_t to;        /* ramp end */
    int32_t amp;       /* sine amplitude */
    uint64_t start_us; /* simulated time the motion began */
    uint64_t dur_us;   /* ramp duration, sine period */
    int32_t sd;        /* noise standard deviation, thousandths; 0: none */
} sim_motion_t;

typedef struct sim {
    const product_t *prod;
    int32_t values[PRODUCT_MAX_INPUTS]; /* thousandths of the input's unit */
    sim_motion_t motion[PRODUCT_MAX_INPUTS];
    sim_replay_t replay;
    uint64_t seed;
    uint64_t t_us;    /* simulated time (sim_step) */
    uint32_t last_us; /* the board's clock at the last sim_step */
    bool stepped;     /* sim_step was called */
    uint32_t faults;  /* bit i: the product's faults[i] is on */
} sim_t;

/* Start with the product's initial input values, no fault, no motion,
 * seed SIM_SEED_DEFAULT. */
void sim_init(sim_t *s, const product_t *p);

/* The noise generator's seed (any value); set before the first change. */
void sim_seed(sim_t *s, uint64_t seed);

/*
 * Advance the simulated time to the board's clock now_us (microseconds,
 * wrapping; steps shorter than half the clock's range) and compute
 * values[] for it. Call before each sample.
 */
void sim_step(sim_t *s, uint32_t now_us);

/* A value as the lines and replay files write it ("12.5", in the input's
 * unit) into thousandths, within +-lim: false if not such a number. */
bool sim_value(const char *str, double lim, int32_t *out);

/* The index of product p's input named name (len bytes), or -1. */
int sim_input_index(const product_t *p, const char *name, size_t len);

/* Input i's motion value now (noise left out): where a ramp or sine
 * would start. */
int32_t sim_motion_now(const sim_t *s, unsigned i);

/* Input i: held at v; a ramp to `to` over dur_us (> 0); a sine of
 * amplitude amp around its value now, period period_us (> 0), starting
 * at that value going up; noise of standard deviation sd (0: none).
 * Values in thousandths, checked by the caller. */
void sim_hold(sim_t *s, unsigned i, int32_t v);
void sim_ramp(sim_t *s, unsigned i, int32_t to, uint64_t dur_us);
void sim_sine(sim_t *s, unsigned i, int32_t amp, uint64_t period_us);
void sim_noise(sim_t *s, unsigned i, int32_t sd);

/* The product's fault f (index into product_t faults[]) on or off. */
void sim_fault(sim_t *s, unsigned f, bool on);

/* Start a replay table loaded for this sim's product (replay_csv_load):
 * its former replay stops, the table's inputs follow it from now. */
void sim_replay_start(sim_t *s, const sim_replay_t *table);

#endif /* LINUX_SIM_H */
