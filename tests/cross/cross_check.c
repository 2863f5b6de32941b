/* Target-side check of the freestanding real-time filter core (afmkit_embed.h) against a header written by
 * `afmkit control export --format c-header --test-vectors M` on the host (scripts/cross.sh builds and runs it).
 *
 * The exported header (found as "afmkit_export.h" on the include path, -I <generated dir>) holds the coefficient
 * set, the plant gain K and M test samples: the disturbance d_n and the host's double-precision reference
 * m_n^ref of the closed loop (static plant y = f + u/K, seed-2 eq. 3, the command acting one sample later):
 *     u_{-1} = 0;  m_n = d_n + u_{n-1}/K;  u_n = step(m_n).
 * This program runs that loop with the target's core (float or double, as the header's afmkit_embed_real says),
 * tracks the worst |m_n - m_n^ref| over all samples, and prints it with the tolerance and PASS or FAIL; the exit
 * status is 0 for PASS, 1 for FAIL (on bare-metal targets the startup code turns it into a semihosting exit).
 * A non-finite m_n or a skipped sample fails. On Linux targets it also times the step (samples/s of the emulated or
 * real target); on ARMv7-M it counts SysTick ticks of the processor clock per step (cycles on hardware; under
 * QEMU -icount shift=0 on MPS2, instructions / 40).
 *
 * C99, no heap; needs only printf from the C library (newlib/rdimon on the Cortex-M, glibc on Linux). */
#if defined(__linux__)
#define _POSIX_C_SOURCE 199309L /* clock_gettime */
#include <time.h>
#endif
#include <math.h>
#include <stdio.h>

#include "afmkit_export.h"

#if defined(__aarch64__)
#define CROSS_TARGET "aarch64"
#elif defined(__ARM_ARCH_7EM__)
#define CROSS_TARGET "armv7e-m (Cortex-M4)"
#elif defined(__arm__)
#define CROSS_TARGET "arm"
#else
#define CROSS_TARGET "host"
#endif

/* Runs the closed loop over the exported test samples from a reset filter; returns the worst absolute deviation
 * from the reference (+inf when a sample is not finite) and its index in *worst_index. */
static double closed_loop_worst_error(afmkit_embed_filter* filter, long* worst_index) {
  afmkit_embed_real command = 0; /* u_{n-1}: the command acts from the next sample on */
  double worst = 0.0;
  long n;
  *worst_index = 0;
  afmkit_embed_reset(filter);
  for (n = 0; n < (long)AFMKIT_EXPORT_TEST_SAMPLES; ++n) {
    /* m_n = d_n + u_{n-1}/K, evaluated as the header writes it (AFMKIT_EXPORT_GAIN is a double constant, so in
     * double, as the exporter's own host check does); the core gets it rounded to its precision */
    const double measured = afmkit_export_test_input[n] + command / AFMKIT_EXPORT_GAIN;
    double error = fabs(measured - afmkit_export_test_expected[n]);
    if (!(error == error) || error > 1e300) { /* NaN or inf: fails whatever the tolerance */
      error = HUGE_VAL;
    }
    if (error > worst) {
      worst = error;
      *worst_index = n;
    }
    command = afmkit_embed_step(filter, (afmkit_embed_real)measured);
  }
  return worst;
}

#if defined(__linux__)
static double seconds_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Steps the filter on the test input (open loop, repeated) for at least 0.1 s; returns samples per second. */
static double samples_per_second(afmkit_embed_filter* filter) {
  volatile afmkit_embed_real sink = 0; /* keeps the steps from being optimised away */
  long steps = 0;
  const double start = seconds_now();
  double elapsed = 0.0;
  do {
    long n;
    for (n = 0; n < (long)AFMKIT_EXPORT_TEST_SAMPLES; ++n) {
      sink = afmkit_embed_step(filter, afmkit_export_test_input[n]);
    }
    steps += (long)AFMKIT_EXPORT_TEST_SAMPLES;
    elapsed = seconds_now() - start;
  } while (elapsed < 0.1 || steps < 1000);
  (void)sink;
  afmkit_embed_reset(filter);
  return (double)steps / elapsed;
}
#elif defined(__ARM_ARCH_7EM__) || defined(__ARM_ARCH_7M__)
/* SysTick (in every ARMv7-M core), counting down at the processor clock (CLKSOURCE = 1): on hardware, cycles; under
 * QEMU's MPS2 the clock is 25 MHz of virtual time, which with `-icount shift=0` (1 ns per instruction) is one tick
 * per 40 instructions. */
#define CROSS_SYST_CSR (*(volatile unsigned long*)0xE000E010u)
#define CROSS_SYST_RVR (*(volatile unsigned long*)0xE000E014u)
#define CROSS_SYST_CVR (*(volatile unsigned long*)0xE000E018u)

/* Steps the filter on the test input (open loop, repeated) in blocks of 1000 and returns SysTick ticks per step. */
static double ticks_per_step(afmkit_embed_filter* filter) {
  volatile afmkit_embed_real sink = 0;
  unsigned long ticks = 0;
  long block, k, n = 0;
  CROSS_SYST_RVR = 0xFFFFFFul; /* 24-bit counter; a block of 1000 steps stays far below a wrap */
  CROSS_SYST_CVR = 0;
  CROSS_SYST_CSR = 5ul; /* enable, processor clock, no interrupt */
  for (block = 0; block < 20; ++block) {
    const unsigned long start = CROSS_SYST_CVR;
    for (k = 0; k < 1000; ++k) {
      sink = afmkit_embed_step(filter, afmkit_export_test_input[n]);
      n = n + 1 < (long)AFMKIT_EXPORT_TEST_SAMPLES ? n + 1 : 0;
    }
    ticks += (start - CROSS_SYST_CVR) & 0xFFFFFFul;
  }
  CROSS_SYST_CSR = 0;
  (void)sink;
  afmkit_embed_reset(filter);
  return (double)ticks / 20000.0;
}
#endif

int main(void) {
  static afmkit_embed_real state[AFMKIT_EXPORT_STATE_SIZE]; /* no heap: the state lives in .bss */
  afmkit_embed_filter filter;
  long worst_index = 0;
  double worst;
  int pass;
  const int init_status = afmkit_embed_init(&filter, &afmkit_export_coefficients, state, AFMKIT_EXPORT_STATE_SIZE);

  printf("afmkit cross check: target %s, %s precision (afmkit_embed_real: %u bytes), %ld samples, state size %ld\n",
         CROSS_TARGET, sizeof(afmkit_embed_real) == sizeof(float) ? "float" : "double",
         (unsigned)sizeof(afmkit_embed_real), (long)AFMKIT_EXPORT_TEST_SAMPLES, (long)AFMKIT_EXPORT_STATE_SIZE);
  if (init_status != 0) {
    printf("afmkit_embed_init failed with status %d\nFAIL\n", init_status);
    return 1;
  }
  if (afmkit_embed_state_size(&afmkit_export_coefficients) != (size_t)AFMKIT_EXPORT_STATE_SIZE) {
    printf("AFMKIT_EXPORT_STATE_SIZE %ld differs from afmkit_embed_state_size %ld\nFAIL\n",
           (long)AFMKIT_EXPORT_STATE_SIZE, (long)afmkit_embed_state_size(&afmkit_export_coefficients));
    return 1;
  }
  printf("footprint: coefficient set %u B + arrays %u B (%u pairs, %u circles, %u reals), filter %u B, state %u B\n",
         (unsigned)sizeof(afmkit_embed_coefficients),
         (unsigned)(sizeof(afmkit_embed_real) *
                    (AFMKIT_EMBED_PAIR_STRIDE * afmkit_export_coefficients.pairs +
                     AFMKIT_EMBED_CIRCLE_STRIDE * afmkit_export_coefficients.circles +
                     AFMKIT_EMBED_REAL_STRIDE * afmkit_export_coefficients.reals)),
         (unsigned)afmkit_export_coefficients.pairs, (unsigned)afmkit_export_coefficients.circles,
         (unsigned)afmkit_export_coefficients.reals, (unsigned)sizeof(afmkit_embed_filter),
         (unsigned)sizeof(state));
  worst = closed_loop_worst_error(&filter, &worst_index);
  /* the exported disturbance is within the input limit: a skipped sample would be a fault of the port */
  pass = worst <= (double)AFMKIT_EXPORT_TEST_TOLERANCE && filter.skipped == 0;
  printf("worst |m - m_ref| = %.3e (sample %ld), tolerance %.3e\n", worst, worst_index,
         (double)AFMKIT_EXPORT_TEST_TOLERANCE);
  if (filter.skipped != 0) {
    printf("%lu samples skipped by the filter (none expected)\n", (unsigned long)filter.skipped);
  }
#if defined(__linux__)
  printf("samples/s: %.3e (step only, this machine or emulator)\n", samples_per_second(&filter));
#elif defined(__ARM_ARCH_7EM__) || defined(__ARM_ARCH_7M__)
  printf("SysTick ticks per step: %.3f (processor clock)\n", ticks_per_step(&filter));
#endif
  printf("%s\n", pass ? "PASS" : "FAIL");
  return pass ? 0 : 1;
}
