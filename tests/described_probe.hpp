#pragma once
// One layer of ranges (issue 26): for an options struct that describes itself (afmkit/core/describe.hpp), every
// range its describe() declares — the one --help shows and the command line checks — is the range its validation
// enforces. The probe sets each described field just outside each finite end of its range (and to NaN), expects
// afmkit::InvalidParameter naming the field's key, and restores it; the defaults must pass.
#include <cmath>
#include <functional>
#include <limits>
#include "afmkit/core/source_location.hpp"
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "afmkit/core/describe.hpp"
#include "afmkit/core/error.hpp"

namespace afmkit_test {

class DescribedRangeProbe {
 public:
  struct Case {
    std::string key;
    std::string what;              // the bad value, for the failure message
    std::function<void()> set;     // puts the bad value into the field
    std::function<void()> restore;  // puts the default back
  };
  std::vector<Case> cases;
  std::vector<std::string> defaults_outside;  // keys whose default is outside their own range

  void real(const char* key, double& field, const char*, const char*, afmkit::Range r,
            afmkit::SourceLocation = afmkit::SourceLocation::current()) {
    double* f = &field;
    const double keep = field;
    if (!r.contains(keep)) defaults_outside.emplace_back(key);
    const auto add = [&](double bad, std::string what) {
      cases.push_back({key, std::move(what), [f, bad] { *f = bad; }, [f, keep] { *f = keep; }});
    };
    constexpr double inf = std::numeric_limits<double>::infinity();
    if (r.lo > -1e307) add(r.lo_open ? r.lo : std::nextafter(r.lo, -inf), "just below the range");
    if (r.hi < 1e307) add(r.hi_open ? r.hi : std::nextafter(r.hi, inf), "just above the range");
    add(std::nan(""), "NaN");
  }
  template <class Int>
  void integer(const char* key, Int& field, const char*, long lo, long hi,
               afmkit::SourceLocation = afmkit::SourceLocation::current()) {
    Int* f = &field;
    const Int keep = field;
    if (keep < lo || keep > hi) defaults_outside.emplace_back(key);
    if (lo > static_cast<long>(std::numeric_limits<Int>::min()))
      cases.push_back({key, "lo - 1", [f, lo] { *f = static_cast<Int>(lo - 1); }, [f, keep] { *f = keep; }});
    if (hi < static_cast<long>(std::numeric_limits<Int>::max()))
      cases.push_back({key, "hi + 1", [f, hi] { *f = static_cast<Int>(hi + 1); }, [f, keep] { *f = keep; }});
  }
  template <class Enum>
  void choice(const char*, Enum&, const char*, std::initializer_list<afmkit::Choice<Enum>>,
              afmkit::SourceLocation = afmkit::SourceLocation::current()) {}
};

/// Checks the one layer of ranges of `options` (its described fields) with `check` (usually validate()).
template <class Options, class Check>
void expect_described_ranges_checked(Options options, Check check) {
  DescribedRangeProbe probe;
  Options::describe(probe, options);  // the probe keeps pointers into `options`
  EXPECT_TRUE(probe.defaults_outside.empty()) << "default outside its declared range: " << probe.defaults_outside[0];
  ASSERT_FALSE(probe.cases.empty());
  EXPECT_NO_THROW(check(options));
  for (const auto& c : probe.cases) {
    c.set();
    try {
      check(options);
      ADD_FAILURE() << c.key << " " << c.what << " was accepted";
    } catch (const afmkit::InvalidParameter& e) {
      EXPECT_EQ(e.parameter(), c.key) << c.what << ": " << e.what();
    }
    c.restore();
  }
}

}  // namespace afmkit_test
