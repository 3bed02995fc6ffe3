// Character classes and layout skipping shared by the Part 21 scanner and the
// parameter decoder (internal to frontend/part21). Classes come from one
// 256-entry table, so each test is a load and a mask.
#pragma once

#include <cstdint>

namespace stepnc::p21::lex {

enum : uint8_t {
  kSpace = 1,         ///< space, tab, CR, LF, FF, VT
  kDigit = 2,
  kLetter = 4,        ///< A-Z a-z
  kUnderscore = 8,
  kHex = 16,          ///< 0-9 A-F a-f
  kLower = 32,        ///< a-z
  kBang = 64,         ///< '!' (user-defined keywords)
};

struct ClassTable {
  uint8_t c[256] = {};
  constexpr ClassTable() {
    for (int i : {' ', '\t', '\r', '\n', '\f', '\v'})
      c[i] = kSpace;
    for (int i = '0'; i <= '9'; ++i)
      c[i] = kDigit | kHex;
    for (int i = 'A'; i <= 'Z'; ++i)
      c[i] = kLetter | (i <= 'F' ? kHex : 0);
    for (int i = 'a'; i <= 'z'; ++i)
      c[i] = kLetter | kLower | (i <= 'f' ? kHex : 0);
    c[static_cast<int>('_')] = kUnderscore;
    c[static_cast<int>('!')] = kBang;
  }
};
inline constexpr ClassTable kClasses;

inline uint8_t classOf(char ch) { return kClasses.c[static_cast<uint8_t>(ch)]; }
inline bool isDigit(char c) { return classOf(c) & kDigit; }
inline bool isLetter(char c) { return classOf(c) & kLetter; }
inline bool isLower(char c) { return classOf(c) & kLower; }
inline bool isKeywordChar(char c) { return classOf(c) & (kLetter | kDigit | kUnderscore); }
inline bool isKeywordStart(char c) { return classOf(c) & (kLetter | kUnderscore | kBang); }
inline bool isHexDigit(char c) { return classOf(c) & kHex; }
inline bool isSpace(char c) { return classOf(c) & kSpace; }

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
