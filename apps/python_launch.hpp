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

/// Whether the module file afmkit/<module>.py of the package is next to this program (a check before computing).
bool python_module_found(const std::string& module);

/// Runs `function(argv)` of the module afmkit.<module> (a plain module file) in a child Python interpreter, the
/// package's folder first on PYTHONPATH, and waits for it: its exit status (its messages go to this process's
/// standard error). InputError when the package is not found or the interpreter cannot be started.
int run_python_function(const std::string& module, const std::string& function, const std::vector<std::string>& args);

}  // namespace afmkit::cli
