#pragma once
// Where a call was written: the file and line of the caller, as a defaulted last argument
// (`SourceLocation where = SourceLocation::current()`), as std::source_location gives them. Written on the compilers'
// builtins because the fuzz build's clang 14 has no std::source_location with this libstdc++ (docs/development.md).
namespace afmkit {

class SourceLocation {
 public:
  /// The location of the call that evaluates this default argument (the builtins take the outermost call site).
  static constexpr SourceLocation current(const char* file = __builtin_FILE(), unsigned line = __builtin_LINE()) noexcept {
    return SourceLocation(file, line);
  }
  constexpr SourceLocation() noexcept = default;
  constexpr const char* file_name() const noexcept { return file_; }
  constexpr unsigned line() const noexcept { return line_; }

 private:
  constexpr SourceLocation(const char* file, unsigned line) noexcept : file_(file), line_(line) {}
  const char* file_ = "";
  unsigned line_ = 0;
};

}  // namespace afmkit
