#pragma once
// afmkit scan with recorded = FILE: a recorded spiral filtered offline (docs/scan.md#recorded-data).
#include "afmkit/io/params.hpp"
#include "command.hpp"

namespace afmkit::cli {
void run_recorded(const io::ParamSet& p, Captured* capture);
}
