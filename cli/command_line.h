// A small declarative command-line parser for the subcommands: options are declared with their
// help text, parsed, validated (numbers must be finite and in range) and printed by --help.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace mq::cli {

// The exit statuses of every command, for scripts and render-farm schedulers: 1 and 2 are not
// worth retrying with the same input, 3 may be (a bug, or the OpenCL device failing).
inline constexpr const char* kExitStatus =
    "exit status: 0 done; 1 bad input or an impossible job (one line on stderr says which);\n"
    "  2 bad usage (an unknown option or a value out of range); 3 internal error (a bug in\n"
    "  meshquilt, or the OpenCL device failed).\n";

// Wrong usage: the CLI prints the message and a hint to --help, and exits with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CommandLine {
 public:
  CommandLine(std::string command, std::string synopsis, std::string description);

  // --name (no value).
  void flag(const std::string& name, const std::string& help);
  // --name VALUE... taking `arity` values; `fallback` is the default shown in --help ("" none).
  void option(const std::string& name, const std::string& value_names, const std::string& help,
              const std::string& fallback = "", int arity = 1);
  // A required positional argument.
  void positional(const std::string& name, const std::string& help);

  // Parses argv[first..argc). Returns false when --help was given (help already printed).
  // Throws UsageError for unknown options, missing values or positionals.
  bool parse(int argc, char** argv, int first);

  bool has(const std::string& name) const;
  std::string get(const std::string& name) const;  // value, default, or "" when absent
  std::string get(const std::string& name, int index) const;
  std::string positional_value(const std::string& name) const;
  // Numeric getters: throw UsageError naming the option for malformed, NaN or out-of-range.
  double get_double(const std::string& name, int index = 0, double min = -1e300,
                    double max = 1e300) const;
  long long get_int(const std::string& name, long long min, long long max) const;

  std::string help() const;

 private:
  struct Option {
    std::string name, value_names, help, fallback;
    int arity = 0;
  };
  const Option* find(const std::string& name) const;

  std::string command_, synopsis_, description_;
  std::vector<Option> options_;
  std::vector<std::pair<std::string, std::string>> positionals_;
  std::map<std::string, std::vector<std::string>> values_;
  std::map<std::string, std::string> positional_values_;
};

// A range "A-B" with 0 <= A <= B as the whole text (embed --frames, edit --ids): true with a and
// b set, false for anything else.
bool parse_range(const std::string& text, int& a, int& b);

// A name with one printf-style frame number (%d or %0Nd; %% is a literal %): the files of a
// sequence (embed --frames, surface --swatch-frames). Throws UsageError naming `option` for a
// pattern without exactly one frame number.
class FramePattern {
 public:
  FramePattern(const std::string& pattern, const char* option);
  std::string operator()(int frame) const;

 private:
  std::string pattern_;
  size_t at_ = 0, end_ = 0;
  int width_ = 0;
};

// The frames A-B of --frames (0 <= A <= B, at most 100000 frames). Throws UsageError otherwise.
std::pair<int, int> frame_range(const std::string& text);

}  // namespace mq::cli
