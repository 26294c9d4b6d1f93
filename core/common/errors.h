// Typed exceptions thrown by meshquilt. Every public function documents which it throws.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace mq {

// Base of every meshquilt error; what() is a single line suitable for the CLI.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Malformed files, NaN, impossible parameters: the caller's input is wrong.
class InvalidInput : public Error {
 public:
  using Error::Error;
};

// A mesh lacks a topological property the algorithm needs (manifoldness, closedness, ...).
class TopologyError : public Error {
 public:
  using Error::Error;
};

// A numerical solve failed (factorisation, non-convergence).
class SolverFailure : public Error {
 public:
  using Error::Error;
};

// The OpenCL platform/device reported an error.
class DeviceError : public Error {
 public:
  using Error::Error;
};

// An internal invariant was violated: a bug in meshquilt, not in the input.
class InternalError : public Error {
 public:
  using Error::Error;
};

namespace detail {
template <typename... Args>
std::string concat(const Args&... args) {
  std::ostringstream os;
  (os << ... << args);
  return os.str();
}
// text with every byte that is not printable UTF-8 (control characters, NUL, malformed
// sequences) written as \xNN, so that a message quoting a file's bytes stays one readable line
// and is not cut at a NUL (issue 14).
inline std::string printable(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  const auto hex = [&](unsigned char c) {
    const char* digits = "0123456789abcdef";
    out += "\\x";
    out += digits[c >> 4];
    out += digits[c & 15];
  };
  for (size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    int n = c < 0x80 ? 0 : (c >> 5) == 6 ? 1 : (c >> 4) == 14 ? 2 : (c >> 3) == 30 ? 3 : -1;
    bool ok = n >= 0 && i + static_cast<size_t>(n) < text.size() + (n == 0 ? 1 : 0);
    for (int k = 1; ok && k <= n; ++k)
      ok = (static_cast<unsigned char>(text[i + static_cast<size_t>(k)]) >> 6) == 2;
    if (n == 0 && (c < 0x20 || c == 0x7f)) ok = false;
    if (!ok) {
      hex(c);
      ++i;
    } else {
      out.append(text, i, static_cast<size_t>(n) + 1);
      i += static_cast<size_t>(n) + 1;
    }
  }
  return out;
}

}  // namespace detail

}  // namespace mq

// Throws ErrorType with the message, prefixed by the source location in debug-friendly form.
#define MQ_THROW(ErrorType, ...) throw ErrorType(::mq::detail::concat(__VA_ARGS__))

// Safety check that throws ErrorType(message) when cond is false.
#define MQ_CHECK(cond, ErrorType, ...)             \
  do {                                             \
    if (!(cond)) MQ_THROW(ErrorType, __VA_ARGS__); \
  } while (0)

// Internal invariant; names file and line since it indicates a bug.
#define MQ_ASSERT(cond)                                                                       \
  do {                                                                                        \
    if (!(cond))                                                                              \
      throw ::mq::InternalError(                                                              \
          ::mq::detail::concat(__FILE__, ":", __LINE__, ": internal check failed: ", #cond)); \
  } while (0)
