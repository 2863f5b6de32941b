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
 *  - A handle must not be used from two threads at the same time (destroy counts as a use); different handles are
 *    independent.
 *  - afmkit_filter_step / _step_block do not allocate, lock or call the system: safe in a real-time loop.
 *
 * Handles: a handle is an opaque checked value, not the address of the filter. Every function looks it up in a
 * library table (one atomic load, no lock) before touching the filter, so a destroyed handle (use after destroy,
 * double destroy) or a foreign value gives AFMKIT_INVALID_HANDLE (NaN from afmkit_filter_step, 0 from the size and
 * counter queries, a message from afmkit_filter_last_error) and never reads freed memory. Limits: at most 4096
 * filters may be alive at once (creation fails beyond, message in `error`); the 4096 table slots are all used once
 * before any is reused, then reused oldest first, and a stale handle would be taken for a live one only after 2^50
 * (32-bit systems: 2^18) create/destroy cycles of its slot; a forged value that copies a live handle is
 * indistinguishable from it.
 *
 * Inputs: a sample that is NaN, infinite or larger in magnitude than the input limit (default
 * AFMKIT_DEFAULT_INPUT_LIMIT = 1e150, afmkit_filter_set_input_limit) is skipped (not clamped): the previous output is
 * returned, the skipped-sample counter raised, the state coasts; so the state can never overflow (argument in
 * realtime_filter.hpp).
 *
 * Number of harmonics N: 1 ... 10000 for the zero-order-hold form (O(N^2) set-up: about 40 ms at N = 1000, about 4
 * seconds at N = 10000; O(N) memory) and 1 ... 100000 for the block form (O(N) set-up). Couplings that make the
 * zero-order-hold modal basis ill-conditioned are accepted only up to N = 200 (dense fallback).
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
#define AFMKIT_INVALID_HANDLE 5   /* the handle was destroyed or not returned by afmkit_filter_create* */

/* Default largest accepted |sample| (afmkit_filter_set_input_limit). */
#define AFMKIT_DEFAULT_INPUT_LIMIT 1e150

/* Discretisation forms (realtime_filter.hpp). */
#define AFMKIT_FORM_ZERO_ORDER_HOLD 0       /* exact ZOH of the controller (default) */
#define AFMKIT_FORM_BLOCK_ZERO_ORDER_HOLD 1 /* block scheme: each oscillator exact for the held error */

typedef struct afmkit_filter afmkit_filter; /* opaque */

/* Library version, e.g. "0.1.0". */
AFMKIT_C_API const char* afmkit_c_version(void);

/* Filter with the couplings (20): a0 = alpha, a_k = 2 alpha, b_k = -2 beta / k, harmonic 1 rejected, zero-order-hold
 * form. Requires sample_rate > harmonics * rotation_frequency / pi (Nyquist), rotation_frequency > 0,
 * 1 <= harmonics <= 10000, finite alpha and beta, gain > 0. Returns NULL on invalid input (message in `error`). */
AFMKIT_C_API afmkit_filter* afmkit_filter_create(double sample_rate, double rotation_frequency, int harmonics,
                                                 double alpha, double beta, double gain, char* error,
                                                 size_t error_size);

/* General bank: a0, a[k-1] and b[k-1] for k = 1..harmonics, the rejected harmonics (rejected_count >= 1 entries in
 * 1..harmonics; rejected = NULL means {1}), and the form (AFMKIT_FORM_*). harmonics in 1..10000 (zero-order hold) or
 * 1..100000 (block form). Returns NULL on invalid input. */
AFMKIT_C_API afmkit_filter* afmkit_filter_create_general(double sample_rate, double rotation_frequency, int harmonics,
                                                         double a0, const double* a, const double* b, double gain,
                                                         const int* rejected, size_t rejected_count, int form,
                                                         char* error, size_t error_size);

/* Frees the filter (NULL is allowed). A destroyed or foreign handle is ignored (see afmkit_filter_destroy_checked). */
AFMKIT_C_API void afmkit_filter_destroy(afmkit_filter* filter);

/* afmkit_filter_destroy with a status: AFMKIT_OK (also for NULL), AFMKIT_INVALID_HANDLE if the handle was already
 * destroyed or is foreign (nothing is freed then). */
AFMKIT_C_API int afmkit_filter_destroy_checked(afmkit_filter* filter);

/* AFMKIT_OK for a live handle, AFMKIT_NULL_HANDLE for NULL, AFMKIT_INVALID_HANDLE for a destroyed or foreign one. */
AFMKIT_C_API int afmkit_filter_check(const afmkit_filter* filter);

/* Control output for one measured sample. A NaN, infinite or out-of-range sample (|m| > input limit) is skipped:
 * the previous output is returned and the skipped-sample counter raised. Returns NaN for a NULL or invalid handle. */
AFMKIT_C_API double afmkit_filter_step(afmkit_filter* filter, double measured);

/* afmkit_filter_step for count samples; `output` may equal `measured` (in place). */
AFMKIT_C_API int afmkit_filter_step_block(afmkit_filter* filter, const double* measured, double* output, size_t count);

/* Zero state, zero output, counters cleared. */
AFMKIT_C_API int afmkit_filter_reset(afmkit_filter* filter);

/* Bumpless change of the parameters of afmkit_filter_create (the oscillator states are kept, the rejected oscillator
 * rescaled so that the output is continuous when the gain changes). On error the filter is unchanged. */
AFMKIT_C_API int afmkit_filter_set_parameters(afmkit_filter* filter, double sample_rate, double rotation_frequency,
                                              int harmonics, double alpha, double beta, double gain);

/* Largest accepted |sample| (default AFMKIT_DEFAULT_INPUT_LIMIT); larger samples are skipped like NaN. Requires
 * 0 < max_abs_sample <= AFMKIT_DEFAULT_INPUT_LIMIT, else AFMKIT_INVALID_ARGUMENT and the limit is unchanged. Kept by
 * reset, set_parameters and restore_state. */
AFMKIT_C_API int afmkit_filter_set_input_limit(afmkit_filter* filter, double max_abs_sample);

/* The current input limit (NaN for a NULL or invalid handle). */
AFMKIT_C_API double afmkit_filter_input_limit(const afmkit_filter* filter);

/* Number of doubles needed by afmkit_filter_save_state (0 for a NULL or invalid handle). */
AFMKIT_C_API size_t afmkit_filter_state_size(const afmkit_filter* filter);

/* Copies the state into buffer[0 .. afmkit_filter_state_size()-1]. */
AFMKIT_C_API int afmkit_filter_save_state(afmkit_filter* filter, double* buffer, size_t size);

/* Restores a saved state; with the same parameters the future outputs are reproduced bit for bit. A buffer that was
 * not saved by a filter is refused with AFMKIT_INVALID_ARGUMENT and the filter is unchanged: wrong magic or version,
 * sizes out of range, a non-finite entry, counters that are not whole numbers in 0 ... 2^64 - 1 (or more skipped than
 * processed samples), a held output or coordinate larger in magnitude than 1e270 (no filter state fed with samples
 * within the input limit gets there). */
AFMKIT_C_API int afmkit_filter_restore_state(afmkit_filter* filter, const double* buffer, size_t size);

/* Number of skipped (non-finite or out-of-range) samples since creation or reset (0 for a NULL or invalid handle). */
AFMKIT_C_API uint64_t afmkit_filter_skipped_samples(const afmkit_filter* filter);

/* Message of the last failed call on this handle ("" if none). Valid until the next call on the handle. For a NULL
 * or invalid handle a static message saying so. */
AFMKIT_C_API const char* afmkit_filter_last_error(const afmkit_filter* filter);

#ifdef __cplusplus
}
#endif

#endif /* AFMKIT_AFMKIT_C_H */
