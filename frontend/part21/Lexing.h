// Character classes and layout skipping shared by the Part 21 scanner and the
// parameter decoder (internal to frontend/part21).
#pragma once

#include <cstdint>

namespace stepnc::p21::lex {

inline bool isDigit(char c) { return c >= '0' && c <= '9'; }
inline bool isUpper(char c) { return c >= 'A' && c <= 'Z'; }
inline bool isLetter(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }
inline bool isKeywordChar(char c) { return isLetter(c) || isDigit(c) || c == '_'; }
inline bool isKeywordStart(char c) { return isLetter(c) || c == '_' || c == '!'; }
inline bool isHexDigit(char c) {
  return isDigit(c) || (c >= 'A' && c <= 'F') || (c >= 'a' && c <= 'f');
}
inline bool isSpace(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v'; }

/// Result of skipping white space and comments.
enum class Layout : uint8_t { Ok, UnterminatedComment };

/// Skips white space and `/* */` comments starting at `p`. On an unterminated
/// comment, `p` is left at the comment's '/' and the result says so.
inline Layout skipLayout(const char *&p, const char *end) {
  for (;;) {
    while (p < end && isSpace(*p))
      ++p;
    if (p + 1 < end && p[0] == '/' && p[1] == '*') {
      const char *q = p + 2;
      while (q + 1 < end && !(q[0] == '*' && q[1] == '/'))
        ++q;
      if (q + 1 >= end)
        return Layout::UnterminatedComment;
      p = q + 2;
      continue;
    }
    return Layout::Ok;
  }
}

} // namespace stepnc::p21::lex
