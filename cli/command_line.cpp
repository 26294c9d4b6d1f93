#include "cli/command_line.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace mq::cli {

CommandLine::CommandLine(std::string command, std::string synopsis, std::string description)
    : command_(std::move(command)),
      synopsis_(std::move(synopsis)),
      description_(std::move(description)) {
  flag("help", "show this help and exit");
}

void CommandLine::flag(const std::string& name, const std::string& help) {
  options_.push_back({name, "", help, "", 0});
}

void CommandLine::option(const std::string& name, const std::string& value_names,
                         const std::string& help, const std::string& fallback, int arity) {
  options_.push_back({name, value_names, help, fallback, arity});
}

void CommandLine::positional(const std::string& name, const std::string& help) {
  positionals_.emplace_back(name, help);
}

const CommandLine::Option* CommandLine::find(const std::string& name) const {
  for (const auto& o : options_)
    if (o.name == name) return &o;
  return nullptr;
}

bool CommandLine::parse(int argc, char** argv, int first) {
  size_t next_positional = 0;
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg.size() > 2 && arg.compare(0, 2, "--") == 0) {
      std::string name = arg.substr(2), inline_value;
      bool has_inline = false;
      if (const auto eq = name.find('='); eq != std::string::npos) {
        inline_value = name.substr(eq + 1);
        name = name.substr(0, eq);
        has_inline = true;
      }
      const Option* o = find(name);
      if (!o) throw UsageError("unknown option --" + name + " for '" + command_ + "'");
      if (name == "help") {
        std::fputs(help().c_str(), stdout);
        return false;
      }
      std::vector<std::string> vals;
      if (has_inline) {
        if (o->arity != 1) throw UsageError("option --" + name + " does not take '=' syntax");
        vals.push_back(inline_value);
      }
      while (static_cast<int>(vals.size()) < o->arity) {
        // An option where a value belongs ("--size 8 -o x"): too few values, said as such
        // rather than as an unexpected argument further on. "-3" is a value.
        const bool next_is_option =
            i + 1 < argc && argv[i + 1][0] == '-' &&
            !(std::isdigit(static_cast<unsigned char>(argv[i + 1][1])) || argv[i + 1][1] == '.');
        if (i + 1 >= argc || next_is_option)
          throw UsageError("option --" + name + " expects " + o->value_names + " (" +
                           std::to_string(o->arity) + " value" + (o->arity > 1 ? "s" : "") +
                           "), got " + std::to_string(vals.size()));
        vals.emplace_back(argv[++i]);
      }
      if (o->arity == 0) vals.emplace_back("1");
      values_[name] = vals;
    } else if (arg == "-o") {
      if (!find("output")) throw UsageError("unknown option -o for '" + command_ + "'");
      if (i + 1 >= argc) throw UsageError("option -o expects a file name");
      values_["output"] = {argv[++i]};
    } else if (arg == "-h") {
      std::fputs(help().c_str(), stdout);
      return false;
    } else {
      if (next_positional >= positionals_.size())
        throw UsageError("unexpected argument '" + arg + "' for '" + command_ + "'");
      positional_values_[positionals_[next_positional++].first] = arg;
    }
  }
  if (next_positional < positionals_.size())
    throw UsageError("'" + command_ + "' needs " + positionals_[next_positional].first);
  return true;
}

bool CommandLine::has(const std::string& name) const { return values_.count(name) > 0; }

std::string CommandLine::get(const std::string& name) const { return get(name, 0); }

std::string CommandLine::get(const std::string& name, int index) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second.at(index);
  const Option* o = find(name);
  if (o && !o->fallback.empty()) {
    std::istringstream is(o->fallback);
    std::string token;
    for (int k = 0; is >> token; ++k)
      if (k == index) return token;
  }
  return "";
}

std::string CommandLine::positional_value(const std::string& name) const {
  auto it = positional_values_.find(name);
  return it == positional_values_.end() ? std::string() : it->second;
}

double CommandLine::get_double(const std::string& name, int index, double min, double max) const {
  const std::string s = get(name, index);
  double value = 0;
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, value);
  if (s.empty() || ec != std::errc() || ptr != end || !std::isfinite(value))
    throw UsageError("option --" + name + " expects a finite number, got '" + s + "'");
  if (value < min || value > max) {
    std::ostringstream os;
    os << "option --" << name << " must be in [" << min << ", " << max << "], got " << s;
    throw UsageError(os.str());
  }
  return value;
}

long long CommandLine::get_int(const std::string& name, long long min, long long max) const {
  const std::string s = get(name);
  long long value = 0;
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, value);
  if (s.empty() || ec != std::errc() || ptr != end)
    throw UsageError("option --" + name + " expects an integer, got '" + s + "'");
  if (value < min || value > max)
    throw UsageError("option --" + name + " must be in [" + std::to_string(min) + ", " +
                     std::to_string(max) + "], got " + s);
  return value;
}

std::string CommandLine::help() const {
  std::ostringstream os;
  os << "usage: meshquilt " << command_ << " " << synopsis_ << "\n\n" << description_ << "\n";
  if (!positionals_.empty()) {
    os << "\narguments:\n";
    for (const auto& [name, text] : positionals_) os << "  " << name << "\n      " << text << "\n";
  }
  os << "\noptions:\n";
  for (const auto& o : options_) {
    os << "  --" << o.name;
    if (o.name == "output") os << ", -o";
    if (!o.value_names.empty()) os << " " << o.value_names;
    os << "\n      " << o.help;
    if (!o.fallback.empty()) os << " (default: " << o.fallback << ")";
    os << "\n";
  }
  os << "\n" << kExitStatus;
  return os.str();
}

bool parse_range(const std::string& text, int& a, int& b) {
  int used = 0;
  return std::sscanf(text.c_str(), "%d-%d%n", &a, &b, &used) == 2 &&
         used == static_cast<int>(text.size()) && 0 <= a && a <= b;
}

namespace {

std::string unescape_percent(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    out += s[i];
    if (s[i] == '%' && i + 1 < s.size() && s[i + 1] == '%') ++i;
  }
  return out;
}

}  // namespace

FramePattern::FramePattern(const std::string& pattern, const char* option) : pattern_(pattern) {
  int found = 0;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      ++i;
      continue;
    }
    size_t j = i + 1;
    int width = 0;
    while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9' && width < 100)
      width = 10 * width + (pattern[j++] - '0');
    if (j >= pattern.size() || pattern[j] != 'd')
      throw UsageError(std::string(option) + " '" + pattern +
                       "': a frame number is written %d or %0Nd (e.g. walk_%04d.obj)");
    at_ = i;
    end_ = j + 1;
    width_ = width;
    ++found;
    i = j;
  }
  if (found != 1)
    throw UsageError(std::string(option) + " '" + pattern +
                     "' needs exactly one frame number (%d or %0Nd) with --frames");
}

std::string FramePattern::operator()(int frame) const {
  std::string number = std::to_string(frame);
  if (static_cast<int>(number.size()) < width_)
    number.insert(0, static_cast<size_t>(width_) - number.size(), '0');
  return unescape_percent(pattern_.substr(0, at_)) + number +
         unescape_percent(pattern_.substr(end_));
}

std::pair<int, int> frame_range(const std::string& text) {
  int a = 0, b = 0;
  if (!parse_range(text, a, b) || b - a >= 100000)
    throw UsageError("--frames expects A-B with 0 <= A <= B (at most 100000 frames), got '" + text +
                     "'");
  return {a, b};
}

}  // namespace mq::cli
