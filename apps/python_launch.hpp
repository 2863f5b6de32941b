#pragma once
// Commands that are Python programs of the package afmkit (`afmkit report`, `afmkit study run`): the C++ side
// validates what it can, then replaces this process with the Python interpreter afmkit was built with.
#include <string>
#include <vector>

namespace afmkit::cli {

/// Runs `python3 -m afmkit.<module> args...` in place of this process (exit status and signals are the Python
/// program's), with the folder holding the package put first on PYTHONPATH. Returns only by throwing InputError:
/// the package is not next to this program (build/python, or the installed dist-packages), or the interpreter
/// cannot be started.
[[noreturn]] void exec_python_module(const std::string& module, const std::vector<std::string>& args);

}  // namespace afmkit::cli
