// UTF-8 helpers shared by the readers, writers and printers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace stepnc::utf8 {

/// Length of the well-formed UTF-8 sequence starting at s[i], or 0: no
/// overlong forms, no surrogates, nothing above U+10FFFF (Unicode table 3-7).
size_t sequenceLength(std::string_view s, size_t i);

/// Appends code point `cp` (<= U+10FFFF, not a surrogate) encoded as UTF-8.
void append(std::string &out, uint32_t cp);

/// Decodes the code point at s[i] and advances i; an ill-formed sequence
/// yields U+FFFD and advances one byte.
uint32_t next(std::string_view s, size_t &i);

} // namespace stepnc::utf8
