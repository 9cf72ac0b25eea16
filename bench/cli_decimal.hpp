#pragma once
/// \file cli_decimal.hpp
/// A CLI11 transform for integer options. CLI11 2.1 converts integers with base auto-detection ("010" is 8,
/// "0x10" 16) and clamps values out of range (a seed of 2^64 ran as 2^64 - 1); this accepts only decimal
/// digits (after an optional '-' where `allow_minus`), drops leading zeros and refuses values above `max`.
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdlib>
#include <string>

namespace nlosloc::bench {

inline CLI::Validator decimal(unsigned long long max, bool allow_minus = false) {
  return CLI::Validator(
      [max, allow_minus](std::string& v) -> std::string {
        std::string s = v;
        const bool minus = allow_minus && !s.empty() && s[0] == '-';
        if (minus) s.erase(0, 1);
        if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos)
          return std::string("expected a decimal integer") + (allow_minus ? "" : " >= 0") + ", got " + v;
        const auto nz = s.find_first_not_of('0');
        s.erase(0, nz == std::string::npos ? s.size() - 1 : nz);
        errno = 0;
        const unsigned long long x = std::strtoull(s.c_str(), nullptr, 10);
        if (errno == ERANGE || x > max) return "expected at most " + std::to_string(max) + ", got " + v;
        v = (minus ? "-" : "") + s;
        return std::string();
      },
      "INT");
}

}  // namespace nlosloc::bench
