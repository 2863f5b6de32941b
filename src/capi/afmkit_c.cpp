// C API of the real-time filter (include/afmkit/afmkit_c.h): a thin exception-free wrapper over
// afmkit::control::RealtimeFilter. Every entry point catches everything; no exception crosses the C boundary.
#include "afmkit/afmkit_c.h"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <span>
#include <stdexcept>
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

// ---- handle registry (afmkit_c.h, "Handles") ------------------------------------------------------------------
// A handle is not a pointer but the value (generation << (kSlotBits + 1)) | (slot << 1) | 1 (odd, so never equal to
// a real, aligned object address). It is checked against a fixed table of slots before anything is dereferenced:
// a destroyed, stale or foreign handle is rejected without reading freed memory. The generation of a slot is odd
// while a filter lives in it and is incremented on create and on destroy. Lookups are lock-free (one atomic load);
// create/destroy take a mutex. All slots are used once before any is reused, then reused first-in first-out.
constexpr unsigned kSlotBits = 12;
constexpr std::uintptr_t kSlots = std::uintptr_t{1} << kSlotBits;  // at most 4096 live filters
constexpr unsigned kGenShift = kSlotBits + 1;
constexpr std::uintptr_t kGenMask = ~std::uintptr_t{0} >> kGenShift;

struct Slot {
  std::atomic<std::uintptr_t> generation{0};
  std::atomic<afmkit_filter*> filter{nullptr};
};
Slot g_slots[kSlots];

struct Registry {
  std::mutex mutex;
  std::deque<std::uint32_t> free_slots;
  std::uint32_t fresh = 0;  // slots [fresh, kSlots) never used
};
Registry& registry() {
  static Registry r;
  return r;
}

constexpr const char* kInvalidHandle =
    "invalid handle: destroyed, or not returned by afmkit_filter_create (or afmkit_filter_create_general)";

/// The live filter behind `h`, or nullptr for NULL, destroyed and foreign handles. Never dereferences `h`.
afmkit_filter* lookup(const afmkit_filter* h) noexcept {
  const auto v = reinterpret_cast<std::uintptr_t>(h);
  if ((v & 1u) == 0) return nullptr;
  const std::uintptr_t gen = v >> kGenShift;
  const Slot& slot = g_slots[(v >> 1) & (kSlots - 1)];
  if ((gen & 1u) == 0 || slot.generation.load(std::memory_order_acquire) != gen) return nullptr;
  return slot.filter.load(std::memory_order_relaxed);
}

/// AFMKIT_NULL_HANDLE for NULL, AFMKIT_INVALID_HANDLE for a destroyed or foreign handle.
int bad_handle(const afmkit_filter* h) noexcept { return h ? AFMKIT_INVALID_HANDLE : AFMKIT_NULL_HANDLE; }

afmkit_filter* register_filter(afmkit_filter* f) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  std::uintptr_t index;
  if (r.fresh < kSlots) {  // never-used slots first, then the freed ones, oldest first
    index = r.fresh++;
  } else if (!r.free_slots.empty()) {
    index = r.free_slots.front();
    r.free_slots.pop_front();
  } else {
    throw std::runtime_error("too many live filters: at most " + std::to_string(kSlots) +
                             " may exist at once (afmkit_filter_destroy the unused ones)");
  }
  Slot& slot = g_slots[index];
  const std::uintptr_t gen = (slot.generation.load(std::memory_order_relaxed) + 1) & kGenMask;  // odd: live
  slot.filter.store(f, std::memory_order_relaxed);
  slot.generation.store(gen, std::memory_order_release);
  return reinterpret_cast<afmkit_filter*>((gen << kGenShift) | (index << 1) | 1u);
}

/// Unregisters and frees; AFMKIT_INVALID_HANDLE if `h` is not live (double destroy, foreign handle).
int unregister_filter(afmkit_filter* h) {
  const auto v = reinterpret_cast<std::uintptr_t>(h);
  afmkit_filter* f = nullptr;
  {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    f = lookup(h);
    if (!f) return AFMKIT_INVALID_HANDLE;
    const std::uintptr_t index = (v >> 1) & (kSlots - 1);
    Slot& slot = g_slots[index];
    slot.generation.store((slot.generation.load(std::memory_order_relaxed) + 1) & kGenMask, std::memory_order_release);
    slot.filter.store(nullptr, std::memory_order_relaxed);
    r.free_slots.push_back(static_cast<std::uint32_t>(index));
  }
  delete f;
  return AFMKIT_OK;
}

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
  guarded(msg, [&] {
    auto f = std::make_unique<afmkit_filter>(afmkit_filter{make(), {}});
    out = register_filter(f.get());
    f.release();
  });
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
    const SampledForm sampled = form_from(form);
    const int max_n = sampled == SampledForm::BlockZeroOrderHold ? RealtimeFilter::kMaxHarmonicsBlock
                                                                 : RealtimeFilter::kMaxHarmonics;
    if (harmonics < 1 || harmonics > max_n)  // before reading a[], b[]
      throw afmkit::InvalidParameter("harmonics", "harmonics = " + std::to_string(harmonics) +
                                                      " is out of range: must be an integer in [1, " +
                                                      std::to_string(max_n) + "] for this form");
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
                          sample_rate, sampled);
  });
}

void afmkit_filter_destroy(afmkit_filter* filter) { (void)afmkit_filter_destroy_checked(filter); }

int afmkit_filter_destroy_checked(afmkit_filter* filter) {
  if (!filter) return AFMKIT_OK;
  return unregister_filter(filter);
}

int afmkit_filter_check(const afmkit_filter* filter) { return lookup(filter) ? AFMKIT_OK : bad_handle(filter); }

double afmkit_filter_step(afmkit_filter* handle, double measured) {
  afmkit_filter* filter = lookup(handle);
  if (!filter) return std::numeric_limits<double>::quiet_NaN();
  return filter->filter.step(measured);
}

int afmkit_filter_step_block(afmkit_filter* handle, const double* measured, double* output, size_t count) {
  afmkit_filter* filter = lookup(handle);
  if (!filter) return bad_handle(handle);
  if (count > 0 && (!measured || !output)) {
    filter->last_error = "step_block: measured and output must not be NULL";
    return AFMKIT_NULL_HANDLE;
  }
  if (count > 0)  // the vectorised block path, the same bits as step() per sample
    filter->filter.step_block(std::span<const double>(measured, count), std::span<double>(output, count));
  return AFMKIT_OK;
}

int afmkit_filter_reset(afmkit_filter* handle) {
  afmkit_filter* filter = lookup(handle);
  if (!filter) return bad_handle(handle);
  filter->filter.reset();
  return AFMKIT_OK;
}

int afmkit_filter_set_parameters(afmkit_filter* handle, double sample_rate, double rotation_frequency, int harmonics,
                                 double alpha, double beta, double gain) {
  afmkit_filter* filter = lookup(handle);
  if (!filter) return bad_handle(handle);
  return guarded(filter->last_error, [&] {
    const auto& old = filter->filter.controller();
    filter->filter.reconfigure(
        OscillatorBank::with_couplings(rotation_frequency, harmonics, alpha, beta, gain, old.rejected()), sample_rate);
  });
}

int afmkit_filter_set_input_limit(afmkit_filter* handle, double max_abs_sample) {
  afmkit_filter* filter = lookup(handle);
  if (!filter) return bad_handle(handle);
  return guarded(filter->last_error, [&] { filter->filter.set_input_limit(max_abs_sample); });
}

double afmkit_filter_input_limit(const afmkit_filter* handle) {
  const afmkit_filter* filter = lookup(handle);
  return filter ? filter->filter.input_limit() : std::numeric_limits<double>::quiet_NaN();
}

size_t afmkit_filter_state_size(const afmkit_filter* handle) {
  const afmkit_filter* filter = lookup(handle);
  return filter ? filter->filter.state_size() : 0;
}

int afmkit_filter_save_state(afmkit_filter* handle, double* buffer, size_t size) {
  afmkit_filter* filter = lookup(handle);
  if (!filter) return bad_handle(handle);
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

int afmkit_filter_restore_state(afmkit_filter* handle, const double* buffer, size_t size) {
  afmkit_filter* filter = lookup(handle);
  if (!filter) return bad_handle(handle);
  if (!buffer) {
    filter->last_error = "restore_state: buffer must not be NULL";
    return AFMKIT_NULL_HANDLE;
  }
  return guarded(filter->last_error, [&] { filter->filter.restore_state(std::span<const double>(buffer, size)); });
}

uint64_t afmkit_filter_skipped_samples(const afmkit_filter* handle) {
  const afmkit_filter* filter = lookup(handle);
  return filter ? filter->filter.skipped_samples() : 0;
}

const char* afmkit_filter_last_error(const afmkit_filter* handle) {
  const afmkit_filter* filter = lookup(handle);
  if (filter) return filter->last_error.c_str();
  return handle ? kInvalidHandle : "null handle";
}

}  // extern "C"
