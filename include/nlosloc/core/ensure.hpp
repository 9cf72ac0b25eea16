#pragma once
/// \file ensure.hpp
/// Argument checking: NLOSLOC_ENSURE(cond, msg) throws std::invalid_argument with msg when cond is false.
/// The throwing path is out of line and cold so the check costs one branch on the hot path.
#include <charconv>
#include <stdexcept>
#include <string>

namespace nlosloc {

/// Raised when a numerical step cannot be completed (e.g. a covariance that is not positive definite).
/// The filter that raises it keeps the state it had before the call.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
[[noreturn, gnu::cold, gnu::noinline]] inline void throw_invalid_argument(const std::string& msg) {
  throw std::invalid_argument(msg);
}
[[noreturn, gnu::cold, gnu::noinline]] inline void throw_numerical_error(const std::string& msg) {
  throw NumericalError(msg);
}
/// Shortest round-trip text of a double ("-1", "0.25", "inf", "nan") for error messages.
inline std::string fmt_shortest(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
}  // namespace detail
}  // namespace nlosloc

/// Checks an argument; the message should name the argument and what was expected.
#define NLOSLOC_ENSURE(cond, msg)                                                     \
  do {                                                                                \
    if (__builtin_expect(!(cond), 0)) ::nlosloc::detail::throw_invalid_argument(msg); \
  } while (0)
