#include "support/Utf8.h"

#include <catch2/catch.hpp>

using namespace stepnc;

TEST_CASE("UTF-8 sequences are accepted only when well formed", "[support]") {
  CHECK(utf8::sequenceLength("a", 0) == 1);
  CHECK(utf8::sequenceLength("\xC3\xA9", 0) == 2);
  CHECK(utf8::sequenceLength("\xE2\x98\xBA", 0) == 3);
  CHECK(utf8::sequenceLength("\xF0\x9F\x98\x80", 0) == 4);
  CHECK(utf8::sequenceLength("\xC0\xAF", 0) == 0);          // overlong '/'
  CHECK(utf8::sequenceLength("\xE0\x80\xAF", 0) == 0);      // overlong
  CHECK(utf8::sequenceLength("\xED\xA0\x80", 0) == 0);      // surrogate U+D800
  CHECK(utf8::sequenceLength("\xF4\x90\x80\x80", 0) == 0);  // above U+10FFFF
  CHECK(utf8::sequenceLength("\xE2\x98", 0) == 0);          // truncated
  CHECK(utf8::sequenceLength("\x80", 0) == 0);              // stray continuation byte
}

TEST_CASE("UTF-8 encodes and decodes every plane", "[support]") {
  for (uint32_t cp : {0x41u, 0xE9u, 0x263Au, 0xFFFDu, 0x1F600u, 0x10FFFFu}) {
    std::string s;
    utf8::append(s, cp);
    size_t i = 0;
    CHECK(utf8::next(s, i) == cp);
    CHECK(i == s.size());
  }
  size_t i = 0;
  CHECK(utf8::next("\xFFz", i) == 0xFFFD);
  CHECK(i == 1);
}
