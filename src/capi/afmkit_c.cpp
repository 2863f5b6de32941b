// C API of the real-time filter (include/afmkit/afmkit_c.h): a thin exception-free wrapper over
// afmkit::control::RealtimeFilter. Every entry point catches everything; no exception crosses the C boundary.
#include "afmkit/afmkit_c.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "afmkit/control/realtime_filter.hpp"
#include "afmkit/core/error.hpp"
#include "afmkit/core/version.hpp"

struct afmkit_filter {
  afmkit::control::RealtimeFilter filter;
  std::string last_error;
};

namespace {

using afmkit::control::OscillatorBank;
using afmkit::control::RealtimeFilter;
using afmkit::control::SampledForm;

void write_error(char* buf, std::size_t size, const std::string& msg) {
  if (!buf || size == 0) return;
  const std::size_t n = std::min(size - 1, msg.size());
  std::memcpy(buf, msg.data(), n);
  buf[n] = '\0';
}

/// Runs f, converting exceptions into a status code and a message.
template <class F>
int guarded(std::string& message, F&& f) {
  try {
    f();
    message.clear();
    return AFMKIT_OK;
  } catch (const afmkit::InvalidParameter& e) {
    message = std::string("invalid parameter ") + e.parameter() + ": " + e.what();
    return AFMKIT_INVALID_ARGUMENT;
  } catch (const std::bad_alloc&) {
    message = "out of memory";
    return AFMKIT_INTERNAL_ERROR;
  } catch (const std::exception& e) {
    message = e.what();
    return AFMKIT_INTERNAL_ERROR;
  } catch (...) {
    message = "unknown error";
    return AFMKIT_INTERNAL_ERROR;
  }
}

afmkit_filter* create(char* error, std::size_t error_size, const auto& make) {
  std::string msg;
  afmkit_filter* out = nullptr;
  guarded(msg, [&] { out = new afmkit_filter{make(), {}}; });
  if (!out) write_error(error, error_size, msg);
  else write_error(error, error_size, "");
  return out;
}

SampledForm form_from(int form) {
  if (form == AFMKIT_FORM_ZERO_ORDER_HOLD) return SampledForm::ZeroOrderHold;
  if (form == AFMKIT_FORM_BLOCK_ZERO_ORDER_HOLD) return SampledForm::BlockZeroOrderHold;
  throw afmkit::InvalidParameter("form", "form = " + std::to_string(form) +
                                             " is out of range: must be 0 (zero-order hold) or 1 (block zero-order hold)");
}

}  // namespace

extern "C" {

const char* afmkit_c_version(void) { return afmkit::version; }

afmkit_filter* afmkit_filter_create(double sample_rate, double rotation_frequency, int harmonics, double alpha,
                                    double beta, double gain, char* error, size_t error_size) {
  return create(error, error_size, [&] {
    return RealtimeFilter::with_couplings(sample_rate, rotation_frequency, harmonics, alpha, beta, gain);
  });
}

afmkit_filter* afmkit_filter_create_general(double sample_rate, double rotation_frequency, int harmonics, double a0,
                                            const double* a, const double* b, double gain, const int* rejected,
                                            size_t rejected_count, int form, char* error, size_t error_size) {
  return create(error, error_size, [&] {
    if (harmonics < 1 || harmonics > 100000)
      throw afmkit::InvalidParameter("harmonics", "harmonics = " + std::to_string(harmonics) +
                                                      " is out of range: must be an integer in [1, 100000]");
    if (!a || !b) throw afmkit::InvalidParameter(!a ? "a" : "b", "a and b must point to `harmonics` doubles each");
    std::vector<double> av(a, a + harmonics), bv(b, b + harmonics);
    std::vector<int> rej{1};
    if (rejected) {
      if (rejected_count < 1 || rejected_count > static_cast<size_t>(harmonics))
        throw afmkit::InvalidParameter("rejected_count", "rejected_count = " + std::to_string(rejected_count) +
                                                             " is out of range: must be in [1, harmonics]");
      rej.assign(rejected, rejected + rejected_count);
    }
    return RealtimeFilter(OscillatorBank(rotation_frequency, a0, std::move(av), std::move(bv), gain, std::move(rej)),
                          sample_rate, form_from(form));
  });
}

void afmkit_filter_destroy(afmkit_filter* filter) { delete filter; }

double afmkit_filter_step(afmkit_filter* filter, double measured) {
  if (!filter) return std::numeric_limits<double>::quiet_NaN();
  return filter->filter.step(measured);
}

int afmkit_filter_step_block(afmkit_filter* filter, const double* measured, double* output, size_t count) {
  if (!filter) return AFMKIT_NULL_HANDLE;
  if (count > 0 && (!measured || !output)) {
    filter->last_error = "step_block: measured and output must not be NULL";
    return AFMKIT_NULL_HANDLE;
  }
  for (size_t i = 0; i < count; ++i) output[i] = filter->filter.step(measured[i]);
  return AFMKIT_OK;
}

int afmkit_filter_reset(afmkit_filter* filter) {
  if (!filter) return AFMKIT_NULL_HANDLE;
  filter->filter.reset();
  return AFMKIT_OK;
}

int afmkit_filter_set_parameters(afmkit_filter* filter, double sample_rate, double rotation_frequency, int harmonics,
                                 double alpha, double beta, double gain) {
  if (!filter) return AFMKIT_NULL_HANDLE;
  return guarded(filter->last_error, [&] {
    const auto& old = filter->filter.controller();
    filter->filter.reconfigure(
        OscillatorBank::with_couplings(rotation_frequency, harmonics, alpha, beta, gain, old.rejected()), sample_rate);
  });
}

size_t afmkit_filter_state_size(const afmkit_filter* filter) { return filter ? filter->filter.state_size() : 0; }

int afmkit_filter_save_state(afmkit_filter* filter, double* buffer, size_t size) {
  if (!filter) return AFMKIT_NULL_HANDLE;
  if (!buffer) {
    filter->last_error = "save_state: buffer must not be NULL";
    return AFMKIT_NULL_HANDLE;
  }
  if (size < filter->filter.state_size()) {
    filter->last_error = "save_state: buffer has " + std::to_string(size) + " doubles, needs " +
                         std::to_string(filter->filter.state_size()) + " (afmkit_filter_state_size)";
    return AFMKIT_BUFFER_TOO_SMALL;
  }
  return guarded(filter->last_error, [&] { filter->filter.save_state(std::span<double>(buffer, size)); });
}

int afmkit_filter_restore_state(afmkit_filter* filter, const double* buffer, size_t size) {
  if (!filter) return AFMKIT_NULL_HANDLE;
  if (!buffer) {
    filter->last_error = "restore_state: buffer must not be NULL";
    return AFMKIT_NULL_HANDLE;
  }
  return guarded(filter->last_error, [&] { filter->filter.restore_state(std::span<const double>(buffer, size)); });
}

uint64_t afmkit_filter_skipped_samples(const afmkit_filter* filter) {
  return filter ? filter->filter.skipped_samples() : 0;
}

const char* afmkit_filter_last_error(const afmkit_filter* filter) {
  return filter ? filter->last_error.c_str() : "null handle";
}

}  // extern "C"
