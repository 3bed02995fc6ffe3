// Number formatting shared by every text output: deterministic, locale-free,
// never `-0`, never exponent notation unless asked for.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>

namespace stepnc {

/// Shortest decimal text that reads back as the same double (C++ to_chars);
/// may use exponent notation ("1e-05"). `-0` prints as "0".
std::string formatShortest(double value);

/// Shortest fixed-point text that reads back as the same double: no exponent,
/// `-0` prints as "0". For values that must survive a text round trip
/// exactly (planned motion).
std::string formatExact(double value);

/// Fixed-point with exactly `decimals` digits after the point; `-0.000` prints
/// as "0.000". Non-finite values print as "nan"/"inf" (callers reject them first).
std::string formatFixed(double value, int decimals);

/// Fixed-point with at most `decimals` digits after the point, trailing zeros
/// and a bare point dropped: "95", "97.5". A setting as people write it.
std::string formatTrimmed(double value, int decimals);

/// "(1.0000, -2.5000, 0.0000)": numbers in fixed point, for messages.
std::string formatTuple(std::initializer_list<double> values, int decimals);

/// "#123": a Part 21 instance name as written in files and messages.
std::string hashId(uint64_t id);

} // namespace stepnc
