/* afmkit C API: the real-time first-harmonic-rejection filter (seed-2 controller, eqs. 15, 6, 20) for instrument
 * software in C, LabVIEW (Call Library Function Node) or Python ctypes. Shared library: libafmkit_c.
 *
 * Units: rotation_frequency Omega and the couplings alpha, beta, a_k, b_k, gain K in rad/s; sample_rate in
 * samples/s. The filter returns the control u_n for each measured sample m_n (see realtime_filter.hpp):
 * u_n = -K x_1(t_n), exact zero-order-hold discretisation, O(N) per sample.
 *
 * Conventions:
 *  - Functions never throw or abort; invalid input gives a NULL handle or a non-zero status code.
 *  - Error text: afmkit_filter_create* write it into the caller's buffer `error` (size `error_size`, always
 *    NUL-terminated, may be NULL); the other functions store it in the handle (afmkit_filter_last_error).
 *  - A handle must not be used from two threads at the same time; different handles are independent.
 *  - afmkit_filter_step / _step_block do not allocate, lock or call the system: safe in a real-time loop.
 */
#ifndef AFMKIT_AFMKIT_C_H
#define AFMKIT_AFMKIT_C_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#define AFMKIT_C_API __declspec(dllexport)
#else
#define AFMKIT_C_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes. */
#define AFMKIT_OK 0
#define AFMKIT_INVALID_ARGUMENT 1 /* a parameter out of range, malformed state buffer */
#define AFMKIT_BUFFER_TOO_SMALL 2 /* save_state: the buffer is smaller than afmkit_filter_state_size() */
#define AFMKIT_NULL_HANDLE 3      /* the handle (or a required pointer) is NULL */
#define AFMKIT_INTERNAL_ERROR 4   /* out of memory or another unexpected failure */

/* Discretisation forms (realtime_filter.hpp). */
#define AFMKIT_FORM_ZERO_ORDER_HOLD 0       /* exact ZOH of the controller (default) */
#define AFMKIT_FORM_BLOCK_ZERO_ORDER_HOLD 1 /* block scheme: each oscillator exact for the held error */

typedef struct afmkit_filter afmkit_filter; /* opaque */

/* Library version, e.g. "0.1.0". */
AFMKIT_C_API const char* afmkit_c_version(void);

/* Filter with the couplings (20): a0 = alpha, a_k = 2 alpha, b_k = -2 beta / k, harmonic 1 rejected.
 * Requires sample_rate > harmonics * rotation_frequency / pi (Nyquist), rotation_frequency > 0, harmonics >= 1,
 * finite alpha and beta, gain > 0. Returns NULL on invalid input (message in `error`). */
AFMKIT_C_API afmkit_filter* afmkit_filter_create(double sample_rate, double rotation_frequency, int harmonics,
                                                 double alpha, double beta, double gain, char* error,
                                                 size_t error_size);

/* General bank: a0, a[k-1] and b[k-1] for k = 1..harmonics, the rejected harmonics (rejected_count >= 1 entries in
 * 1..harmonics; rejected = NULL means {1}), and the form (AFMKIT_FORM_*). Returns NULL on invalid input. */
AFMKIT_C_API afmkit_filter* afmkit_filter_create_general(double sample_rate, double rotation_frequency, int harmonics,
                                                         double a0, const double* a, const double* b, double gain,
                                                         const int* rejected, size_t rejected_count, int form,
                                                         char* error, size_t error_size);

/* Frees the filter (NULL is allowed). */
AFMKIT_C_API void afmkit_filter_destroy(afmkit_filter* filter);

/* Control output for one measured sample. A NaN or infinite sample is skipped: the previous output is returned and
 * the skipped-sample counter raised. Returns NaN for a NULL handle. */
AFMKIT_C_API double afmkit_filter_step(afmkit_filter* filter, double measured);

/* afmkit_filter_step for count samples; `output` may equal `measured` (in place). */
AFMKIT_C_API int afmkit_filter_step_block(afmkit_filter* filter, const double* measured, double* output, size_t count);

/* Zero state, zero output, counters cleared. */
AFMKIT_C_API int afmkit_filter_reset(afmkit_filter* filter);

/* Bumpless change of the parameters of afmkit_filter_create (the oscillator states are kept, the rejected oscillator
 * rescaled so that the output is continuous when the gain changes). On error the filter is unchanged. */
AFMKIT_C_API int afmkit_filter_set_parameters(afmkit_filter* filter, double sample_rate, double rotation_frequency,
                                              int harmonics, double alpha, double beta, double gain);

/* Number of doubles needed by afmkit_filter_save_state (0 for a NULL handle). */
AFMKIT_C_API size_t afmkit_filter_state_size(const afmkit_filter* filter);

/* Copies the state into buffer[0 .. afmkit_filter_state_size()-1]. */
AFMKIT_C_API int afmkit_filter_save_state(afmkit_filter* filter, double* buffer, size_t size);

/* Restores a saved state; with the same parameters the future outputs are reproduced bit for bit. */
AFMKIT_C_API int afmkit_filter_restore_state(afmkit_filter* filter, const double* buffer, size_t size);

/* Number of skipped (non-finite) samples since creation or reset. */
AFMKIT_C_API uint64_t afmkit_filter_skipped_samples(const afmkit_filter* filter);

/* Message of the last failed call on this handle ("" if none). Valid until the next call on the handle. */
AFMKIT_C_API const char* afmkit_filter_last_error(const afmkit_filter* filter);

#ifdef __cplusplus
}
#endif

#endif /* AFMKIT_AFMKIT_C_H */
