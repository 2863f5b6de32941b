/* afmkit embedded core (include/afmkit/embed/afmkit_embed.h; docs/embedding.md). Freestanding C99: no heap, no
 * globals, no library calls. Compiled twice on the host: float (default) and double (-DAFMKIT_EMBED_DOUBLE). */
#include "afmkit/embed/afmkit_embed.h"

/* finite without <math.h>: NaN fails x == x, +-inf gives x - x = NaN */
static int afmkit_embed_finite_(afmkit_embed_real x) { return x == x && (x - x) == (x - x); }

size_t afmkit_embed_state_size(const afmkit_embed_coefficients* c) {
  if (!c) return 0;
  return 2u * ((size_t)c->pairs + (size_t)c->circles) + (size_t)c->reals;
}

static int afmkit_embed_all_finite_(const afmkit_embed_real* v, size_t n) {
  size_t i;
  for (i = 0; i < n; ++i)
    if (!afmkit_embed_finite_(v[i])) return 0;
  return 1;
}

static int afmkit_embed_check_(const afmkit_embed_coefficients* c) {
  size_t i;
  if (c->magic != AFMKIT_EMBED_MAGIC || c->version != AFMKIT_EMBED_VERSION ||
      c->precision != AFMKIT_EMBED_PRECISION_BITS)
    return AFMKIT_EMBED_ERR_MAGIC;
  if (c->pairs + (size_t)c->circles + c->reals == 0) return AFMKIT_EMBED_ERR_COEFFICIENTS;
  if ((c->pairs && !c->pair) || (c->circles && !c->circle) || (c->reals && !c->real))
    return AFMKIT_EMBED_ERR_COEFFICIENTS;
  if (!afmkit_embed_finite_(c->input_limit) || !(c->input_limit > 0)) return AFMKIT_EMBED_ERR_VALUE;
  if (!afmkit_embed_all_finite_(c->pair, (size_t)c->pairs * AFMKIT_EMBED_PAIR_STRIDE) ||
      !afmkit_embed_all_finite_(c->circle, (size_t)c->circles * AFMKIT_EMBED_CIRCLE_STRIDE) ||
      !afmkit_embed_all_finite_(c->real, (size_t)c->reals * AFMKIT_EMBED_REAL_STRIDE))
    return AFMKIT_EMBED_ERR_VALUE;
  for (i = 0; i < c->pairs; ++i) { /* damped: |c + i s| < 1 */
    const afmkit_embed_real* p = c->pair + i * AFMKIT_EMBED_PAIR_STRIDE;
    if (!(p[0] * p[0] + p[1] * p[1] < 1)) return AFMKIT_EMBED_ERR_VALUE;
  }
  for (i = 0; i < c->circles; ++i) { /* magic circle: eigenvalues on the unit circle iff |eps| < 2 */
    const afmkit_embed_real e = c->circle[i * AFMKIT_EMBED_CIRCLE_STRIDE];
    if (!(e > -2 && e < 2)) return AFMKIT_EMBED_ERR_VALUE;
  }
  for (i = 0; i < c->reals; ++i) {
    const afmkit_embed_real r = c->real[i * AFMKIT_EMBED_REAL_STRIDE];
    if (!(r > -1 && r < 1)) return AFMKIT_EMBED_ERR_VALUE;
  }
  return AFMKIT_EMBED_OK;
}

void afmkit_embed_reset(afmkit_embed_filter* f) {
  size_t i, n;
  if (!f || !f->coefficients || !f->state) return;
  n = afmkit_embed_state_size(f->coefficients);
  for (i = 0; i < n; ++i) f->state[i] = 0;
  f->held = 0;
  f->skipped = 0;
}

int afmkit_embed_init(afmkit_embed_filter* f, const afmkit_embed_coefficients* c, afmkit_embed_real* state,
                      size_t state_size) {
  int err;
  if (!f || !c || !state) return AFMKIT_EMBED_ERR_NULL;
  f->coefficients = 0;
  f->state = 0;
  err = afmkit_embed_check_(c);
  if (err != AFMKIT_EMBED_OK) return err;
  if (state_size < afmkit_embed_state_size(c)) return AFMKIT_EMBED_ERR_STATE_SIZE;
  f->coefficients = c;
  f->state = state;
  afmkit_embed_reset(f);
  return AFMKIT_EMBED_OK;
}

/* Coasting input of a skipped sample: coast weights . state. */
static afmkit_embed_real afmkit_embed_coast_(const afmkit_embed_coefficients* c, const afmkit_embed_real* q) {
  afmkit_embed_real m = 0;
  uint32_t i;
  const afmkit_embed_real* p = c->pair;
  for (i = 0; i < c->pairs; ++i, p += AFMKIT_EMBED_PAIR_STRIDE, q += 2) m += p[6] * q[0] + p[7] * q[1];
  p = c->circle;
  for (i = 0; i < c->circles; ++i, p += AFMKIT_EMBED_CIRCLE_STRIDE, q += 2) m += p[5] * q[0] + p[6] * q[1];
  p = c->real;
  for (i = 0; i < c->reals; ++i, p += AFMKIT_EMBED_REAL_STRIDE, ++q) m += p[3] * q[0];
  return m;
}

/* Output from the old state, then the state advanced with input m. */
static afmkit_embed_real afmkit_embed_advance_(const afmkit_embed_coefficients* c, afmkit_embed_real* q,
                                               afmkit_embed_real m) {
  afmkit_embed_real u = 0;
  uint32_t i;
  const afmkit_embed_real* p = c->pair;
  for (i = 0; i < c->pairs; ++i, p += AFMKIT_EMBED_PAIR_STRIDE, q += 2) {
    const afmkit_embed_real q1 = q[0], q2 = q[1];
    u += p[4] * q1 + p[5] * q2;
    q[0] = p[0] * q1 - p[1] * q2 + p[2] * m;
    q[1] = p[0] * q2 + p[1] * q1 + p[3] * m;
  }
  p = c->circle;
  for (i = 0; i < c->circles; ++i, p += AFMKIT_EMBED_CIRCLE_STRIDE, q += 2) {
    afmkit_embed_real y1 = q[0];
    const afmkit_embed_real y2 = q[1];
    u += p[3] * y1 + p[4] * y2;
    y1 = y1 - p[0] * y2 + p[1] * m; /* first shear */
    q[0] = y1;
    q[1] = y2 + p[0] * y1 + p[2] * m; /* second shear, with the new y1 */
  }
  p = c->real;
  for (i = 0; i < c->reals; ++i, p += AFMKIT_EMBED_REAL_STRIDE, ++q) {
    const afmkit_embed_real x = q[0];
    u += p[2] * x;
    q[0] = p[0] * x + p[1] * m;
  }
  return u;
}

afmkit_embed_real afmkit_embed_step(afmkit_embed_filter* f, afmkit_embed_real measured) {
  const afmkit_embed_coefficients* c = f->coefficients;
  const afmkit_embed_real limit = c->input_limit;
  if (!(measured <= limit && measured >= -limit)) { /* NaN, +-inf, |m| > limit: skipped, output held */
    ++f->skipped;
    (void)afmkit_embed_advance_(c, f->state, afmkit_embed_coast_(c, f->state));
    return f->held;
  }
  f->held = afmkit_embed_advance_(c, f->state, measured);
  return f->held;
}

void afmkit_embed_step_block(afmkit_embed_filter* f, const afmkit_embed_real* in, afmkit_embed_real* out, size_t n) {
  size_t i;
  for (i = 0; i < n; ++i) out[i] = afmkit_embed_step(f, in[i]);
}
