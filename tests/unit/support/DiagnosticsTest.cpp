#include "support/Diagnostics.h"
#include "support/Format.h"
#include "support/VerifyDiagnostics.h"

#include <catch2/catch.hpp>
#include <sstream>

using namespace stepnc;

TEST_CASE("line and column come from byte offsets, CRLF or LF", "[support]") {
  auto f = SourceFile::fromString("a.stp", "ab\r\ncd\nef");
  CHECK(f->lineCol(0).line == 1);
  CHECK(f->lineCol(4).line == 2);
  CHECK(f->lineCol(5).col == 2);
  CHECK(f->lineCol(7).line == 3);
  CHECK(f->lineText(1) == "ab");
  CHECK(f->lineText(2) == "cd");
  CHECK(f->lineText(3) == "ef");
  CHECK(f->text().data()[f->text().size()] == '\0');
}

TEST_CASE("text diagnostics show location, subject, source line, caret and notes", "[support]") {
  auto f = SourceFile::fromString("part.stp", "#1=A(#2);\n#2=B();\n");
  std::ostringstream os;
  TextDiagnosticPrinter printer(os);
  DiagnosticEngine engine(printer);
  engine.error({f.get(), 5}, "bad reference").entity(1, "A").note({f.get(), 10}, "defined here");
  CHECK(os.str() == "part.stp:1:6: error: #1 A: bad reference\n"
                    "#1=A(#2);\n"
                    "     ^\n"
                    "part.stp:2:1: note: defined here\n"
                    "#2=B();\n"
                    "^\n");
  CHECK(engine.errorCount() == 1);
}

TEST_CASE("json diagnostics are one array with located objects", "[support]") {
  auto f = SourceFile::fromString("x.stp", "abc\n\"q\"");
  std::ostringstream os;
  JsonDiagnosticPrinter printer(os);
  DiagnosticEngine engine(printer);
  engine.warning({f.get(), 4}, "quote \" here").entity(7);
  engine.report(Severity::Remark, {}, "plain");
  engine.finish();
  CHECK(os.str() == "[\n  {\"severity\":\"warning\",\"file\":\"x.stp\",\"line\":2,\"column\":1,"
                    "\"entity_id\":7,\"message\":\"quote \\\" here\"},\n"
                    "  {\"severity\":\"remark\",\"message\":\"plain\"}\n]\n");
}

TEST_CASE("the engine stops after --max-errors errors", "[support]") {
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  engine.setMaxErrors(2);
  for (int i = 0; i < 5; ++i)
    engine.error({}, "e");
  CHECK(engine.limitReached());
  CHECK(engine.errorCount() == 2);
  REQUIRE(c.diags.size() == 3);  // two errors and the "too many errors" note
  CHECK(c.diags[2].severity == Severity::Note);
}

TEST_CASE("warnings can be made errors", "[support]") {
  DiagnosticCollector c;
  DiagnosticEngine engine(c);
  engine.setWarningsAsErrors(true);
  engine.warning({}, "w");
  CHECK(engine.errorCount() == 1);
  CHECK(c.diags[0].severity == Severity::Error);
}

TEST_CASE("number formatting never prints -0", "[support]") {
  CHECK(formatFixed(-0.0001, 3) == "0.000");
  CHECK(formatFixed(-1.5, 3) == "-1.500");
  CHECK(formatShortest(-0.0) == "0");
  CHECK(formatShortest(0.1) == "0.1");
  CHECK(hashId(42) == "#42");
}

TEST_CASE("verifyDiagnostics matches expectations by line, column and text", "[support]") {
  auto f = SourceFile::fromString("v.stp", "/* expected-error@+1:3 {{boom}} */\nxxboom\n"
                                           "/* expected-warning {{careful}} */\n");
  Diagnostic hit;
  hit.loc = {f.get(), 37};  // line 2, column 3
  hit.message = "it went boom";
  Diagnostic warn;
  warn.severity = Severity::Warning;
  warn.loc = {f.get(), 45};
  warn.message = "be careful";
  std::ostringstream os;
  CHECK(verifyDiagnostics(*f, {hit, warn}, os));
  CHECK(os.str().empty());

  Diagnostic wrongCol = hit;
  wrongCol.loc.offset = 36;
  std::ostringstream os2;
  CHECK_FALSE(verifyDiagnostics(*f, {wrongCol, warn}, os2));
  CHECK(os2.str().find("unexpected error") != std::string::npos);
  CHECK(os2.str().find("was not produced: {{boom}}") != std::string::npos);
}

TEST_CASE("json output stays valid UTF-8 whatever the message holds", "[support]") {
  std::ostringstream os;
  JsonDiagnosticPrinter printer(os);
  DiagnosticEngine engine(printer);
  engine.error({}, std::string("bad \xFF byte, good \xC3\xA9, ctl \x01"));
  engine.finish();
  CHECK(os.str() == "[\n  {\"severity\":\"error\",\"message\":\"bad \\ufffd byte, good \xC3\xA9, ctl \\u0001\"}\n]\n");
}
