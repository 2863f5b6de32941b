/* The real-time first-harmonic rejection filter from C (C99), through the C API only (afmkit/afmkit_c.h, shared
 * library libafmkit_c): what instrument software (C, LabVIEW, Python ctypes) does with it.
 *
 * The situation (seed-2 controller): a sample rotates at Omega; the measured height y carries a large first
 * harmonic (the tilt of the sample, which the instrument must remove) on top of the offset and the harmonics
 * 2, 3, ... that are the actual surface (to be kept). The filter is the controller of a loop: each sample it gets
 * the measurement m_n and returns the actuator command u_n; the actuator adds u/gamma to the height (a static plant
 * y = f + u/gamma, seed-2 eq. 3, with the gain K = gamma). In closed loop the filter cancels the first harmonic of
 * y and lets the offset and the other harmonics through.
 *
 * This program
 *   1. creates two filters for a 50 Hz rotation sampled at 10 kHz (200 samples per rotation), N = 10 oscillators
 *      with the couplings alpha, beta of seed-2 eq. (20): the default exact zero-order-hold form
 *      (afmkit_filter_create) and the block form (afmkit_filter_create_general with the same couplings);
 *   2. runs each loop for 300 rotations on the synthetic signal f = offset + tilt (harmonic 1) + harmonics 2 and 3;
 *      the command computed from sample n acts from sample n + 1 on (one sample of delay, as on a real instrument);
 *   3. measures the harmonics of y by a discrete Fourier projection over the last 10 whole rotations and checks:
 *        - the tilt is rejected: reduced by more than 1e9 (exact rejection, up to rounding) by both forms;
 *        - the offset and the harmonics 2, 3 pass: to 1e-9 with the block form (exact pass-through in the samples),
 *          to (Omega h)^2 ~ 1e-3 in amplitude (relative) and phase (rad) with the zero-order-hold form, whose
 *          sampling moves the controller's zeros at k Omega by O((Omega h)^2) (h: the sampling interval);
 *   4. shows the error handling: invalid parameters give NULL and a message naming the parameter, a bad call an
 *      error code with its message, a non-finite sample is skipped and counted, a destroyed handle is recognised;
 *   5. destroys the filters and prints "ok".
 *
 * Units: rotation_frequency Omega and the couplings alpha, beta and the gain K in rad/s, the sample rate in
 * samples/s; the signal in any unit (here nm of height), u in the same unit times rad/s.
 *
 * Build against the installed library: examples/README.md (CMake: afmkit::c; pkg-config: afmkit_c).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <afmkit/afmkit_c.h>

#define PI 3.14159265358979323846

/* The rotation and the sampling. */
#define ROTATION_HZ 50.0          /* rotations per second (3000 rpm) */
#define SAMPLES_PER_ROTATION 200  /* sample rate = 200 * 50 Hz = 10 kHz */
#define ROTATIONS 300             /* rotations simulated */
#define MEASURED_ROTATIONS 10     /* the last rotations, over which the harmonics are measured */

/* The synthetic height f(t) = offset + sum_k F_k cos(k Omega t + phi_k) [nm]. */
static const double kOffset = 3.0;
static const double kAmplitude[4] = {0.0, 50.0, 2.0, 1.0}; /* F_1 (tilt), F_2, F_3 [nm] */
static const double kPhase[4] = {0.0, 0.3, 1.1, -0.7};     /* phi_1, phi_2, phi_3 [rad] */

static double disturbance(double t, double omega) {
  double f = kOffset;
  int k;
  for (k = 1; k <= 3; ++k) f += kAmplitude[k] * cos(k * omega * t + kPhase[k]);
  return f;
}

/* Amplitude and phase of harmonic k (k = 0: the mean) of y[0 .. count-1], sampled at t_n = (first + n) h, by the
 * discrete Fourier projection over whole rotations: y ~ c_0 + sum_k |c_k| cos(k Omega t + arg c_k). */
static void harmonic(const double* y, int count, int first, double h, double omega, int k, double* amplitude,
                     double* phase) {
  double re = 0.0, im = 0.0;
  int n;
  for (n = 0; n < count; ++n) {
    const double angle = k * omega * (first + n) * h;
    re += y[n] * cos(angle);
    im -= y[n] * sin(angle);
  }
  re *= (k == 0 ? 1.0 : 2.0) / count;
  im *= (k == 0 ? 1.0 : 2.0) / count;
  *amplitude = sqrt(re * re + im * im);
  *phase = atan2(im, re);
}

static int failed(const char* what) {
  printf("error: %s\n", what);
  return 1;
}

/* The closed loop for ROTATIONS rotations; the output y of the last MEASURED_ROTATIONS rotations goes to `y`.
 * Sample n: the height is f(t_n) plus the effect of the previous command; the filter reads it (m_n = y_n) and
 * returns the next command. afmkit_filter_step does not allocate, lock or call the system: safe in a real-time
 * loop. Returns the last command (NaN if the handle was invalid). */
static double run_loop(afmkit_filter* filter, double omega, double h, double plant_rate, double* y) {
  const int total = ROTATIONS * SAMPLES_PER_ROTATION, first_kept = total - MEASURED_ROTATIONS * SAMPLES_PER_ROTATION;
  double u = 0.0;
  int n;
  for (n = 0; n < total && u == u; ++n) {
    const double height = disturbance(n * h, omega) + u / plant_rate;
    if (n >= first_kept) y[n - first_kept] = height;
    u = afmkit_filter_step(filter, height);
  }
  return u;
}

int main(void) {
  const double omega = 2.0 * PI * ROTATION_HZ;                   /* Omega [rad/s] */
  const double sample_rate = SAMPLES_PER_ROTATION * ROTATION_HZ; /* [samples/s] */
  const double h = 1.0 / sample_rate;                            /* sampling interval [s] */
  const double zoh_tolerance = (omega * h) * (omega * h);        /* (Omega h)^2 */
  const int harmonics = 10;                                      /* N: oscillators at harmonics 1 .. 10 (+ mean) */
  const double alpha = 0.1 * omega, beta = -0.1 * omega;         /* couplings of eq. (20) [rad/s] */
  const double plant_rate = 20.0 * omega;                        /* gamma [rad/s] of the plant y = f + u/gamma */
  const double gain = plant_rate;                                /* K = gamma: the design rule */
  const int kept = MEASURED_ROTATIONS * SAMPLES_PER_ROTATION;
  const int first_kept = (ROTATIONS - MEASURED_ROTATIONS) * SAMPLES_PER_ROTATION;
  static double y_zoh[MEASURED_ROTATIONS * SAMPLES_PER_ROTATION], y_block[MEASURED_ROTATIONS * SAMPLES_PER_ROTATION];
  double a[10], b[10];
  char message[256];
  afmkit_filter *filter, *block;
  double u, u_block;
  int k, status, ok = 1;

  printf("afmkit C API %s: first-harmonic rejection, Omega = %.4g rad/s, %d samples per rotation, N = %d\n",
         afmkit_c_version(), omega, SAMPLES_PER_ROTATION, harmonics);

  /* ---- 1. create --------------------------------------------------------------------------------------------------
   * The couplings (20) in one call: a0 = alpha, a_k = 2 alpha, b_k = -2 beta / k, harmonic 1 rejected. */
  filter = afmkit_filter_create(sample_rate, omega, harmonics, alpha, beta, gain, message, sizeof message);
  if (!filter) {
    printf("error: afmkit_filter_create: %s\n", message);
    return 1;
  }
  /* The same couplings given one by one, in the block form; rejected = NULL means {1}. */
  for (k = 1; k <= harmonics; ++k) {
    a[k - 1] = 2.0 * alpha;
    b[k - 1] = -2.0 * beta / k;
  }
  block = afmkit_filter_create_general(sample_rate, omega, harmonics, alpha, a, b, gain, NULL, 0,
                                       AFMKIT_FORM_BLOCK_ZERO_ORDER_HOLD, message, sizeof message);
  if (!block) {
    printf("error: afmkit_filter_create_general: %s\n", message);
    afmkit_filter_destroy(filter);
    return 1;
  }

  /* ---- 2. the closed loops ------------------------------------------------------------------------------------- */
  u = run_loop(filter, omega, h, plant_rate, y_zoh);
  if (u != u) return failed("afmkit_filter_step returned NaN (invalid handle)");
  u_block = run_loop(block, omega, h, plant_rate, y_block);
  if (u_block != u_block) return failed("afmkit_filter_step returned NaN (invalid handle)");

  /* ---- 3. the harmonics of the output over the last whole rotations -------------------------------------------- */
  printf("%8s %8s %27s %27s\n", "", "input f", "output y, zero-order hold", "output y, block form");
  printf("%8s %8s %16s %10s %16s %10s\n", "harmonic", "[nm]", "[nm]", "y/f", "[nm]", "y/f");
  for (k = 0; k <= 3; ++k) {
    const double input = k == 0 ? kOffset : kAmplitude[k], input_phase = kPhase[k];
    double zoh, zoh_phase, blk, blk_phase;
    harmonic(y_zoh, kept, first_kept, h, omega, k, &zoh, &zoh_phase);
    harmonic(y_block, kept, first_kept, h, omega, k, &blk, &blk_phase);
    printf("%8d %8g %16.10g %10.3g %16.10g %10.3g\n", k, input, zoh, zoh / input, blk, blk / input);
    if (k == 1) { /* the tilt: rejected (exactly, up to rounding and the decayed transient) */
      ok &= zoh < 1e-9 * input && blk < 1e-9 * input;
    } else { /* the surface: passed, phase included (the mean has phase 0 or pi: compared through its sign) */
      ok &= fabs(zoh - input) < zoh_tolerance * input && fabs(blk - input) < 1e-9 * input;
      if (k > 0) {
        ok &= fabs(remainder(zoh_phase - input_phase, 2.0 * PI)) < zoh_tolerance;
        ok &= fabs(remainder(blk_phase - input_phase, 2.0 * PI)) < 1e-9;
      } else {
        ok &= fabs(zoh_phase) < 1e-12 && fabs(blk_phase) < 1e-12; /* a positive mean, as the input's */
      }
    }
  }
  if (!ok) return failed("the first harmonic is not rejected, or the others do not pass");

  /* ---- 4. errors --------------------------------------------------------------------------------------------------
   * Creation with invalid parameters: NULL, and the message (always NUL-terminated) names the parameter. */
  if (afmkit_filter_create(sample_rate, omega, 0, alpha, beta, gain, message, sizeof message) != NULL)
    return failed("harmonics = 0 was accepted");
  printf("harmonics = 0 refused: %s\n", message);
  if (strstr(message, "harmonics") == NULL) return failed("the message does not name harmonics");

  /* Nyquist: the highest oscillator (N Omega) must lie below pi * sample_rate. */
  if (afmkit_filter_create(harmonics * ROTATION_HZ, omega, harmonics, alpha, beta, gain, message, sizeof message))
    return failed("a sample rate below the Nyquist limit was accepted");
  printf("sample rate %.4g samples/s refused: %s\n", harmonics * ROTATION_HZ, message);
  if (strstr(message, "sample_rate") == NULL) return failed("the message does not name sample_rate");

  /* A failed call on a live filter: a status code, the message in afmkit_filter_last_error, the filter unchanged. */
  status = afmkit_filter_set_input_limit(filter, -1.0);
  printf("input limit -1 refused: status %d (AFMKIT_INVALID_ARGUMENT = %d): %s\n", status, AFMKIT_INVALID_ARGUMENT,
         afmkit_filter_last_error(filter));
  if (status != AFMKIT_INVALID_ARGUMENT || afmkit_filter_last_error(filter)[0] == '\0' ||
      afmkit_filter_input_limit(filter) != AFMKIT_DEFAULT_INPUT_LIMIT)
    return failed("afmkit_filter_set_input_limit(-1) was not refused with its code and message");

  /* A NaN sample (a dropped ADC reading) is skipped: the previous command is held and the sample counted. */
  {
    const double held = afmkit_filter_step(filter, NAN);
    if (afmkit_filter_skipped_samples(filter) != 1 || held != u) return failed("a NaN sample was not skipped");
    printf("NaN sample skipped: command held at %.6g, skipped samples %lu\n", held,
           (unsigned long)afmkit_filter_skipped_samples(filter));
  }

  /* ---- 5. destroy -------------------------------------------------------------------------------------------------
   * A handle is a checked value: once destroyed, every call recognises it instead of reading freed memory. */
  if (afmkit_filter_destroy_checked(filter) != AFMKIT_OK) return failed("afmkit_filter_destroy_checked");
  if (afmkit_filter_check(filter) != AFMKIT_INVALID_HANDLE ||
      afmkit_filter_destroy_checked(filter) != AFMKIT_INVALID_HANDLE)
    return failed("a destroyed handle was not recognised");
  printf("destroyed handle recognised: %s\n", afmkit_filter_last_error(filter));
  afmkit_filter_destroy(block);
  afmkit_filter_destroy(NULL); /* allowed, does nothing */

  printf("ok\n");
  return 0;
}
