#include "support/Format.h"
#include "support/Diagnostics.h"

#include "support/Json.h"

#include <ostream>

namespace stepnc {

const char *severityName(Severity s) {
  switch (s) {
  case Severity::Error: return "error";
  case Severity::Warning: return "warning";
  case Severity::Note: return "note";
  case Severity::Remark: return "remark";
  }
  return "error";
}

namespace {

// Lines longer than this are shown as a window around the caret.
constexpr size_t kMaxShownLine = 120;

std::string subjectPrefix(const Diagnostic &d) {
  if (d.entityId == 0)
    return {};
  std::string s = hashId(d.entityId);
  if (!d.entityName.empty())
    s += " " + d.entityName;
  return s + ": ";
}

} // namespace

void TextDiagnosticPrinter::print(const Diagnostic &d) {
  if (d.loc.valid()) {
    LineCol lc = d.loc.file->lineCol(d.loc.offset);
    os_ << d.loc.file->name() << ':' << lc.line << ':' << lc.col << ": ";
    os_ << severityName(d.severity) << ": " << subjectPrefix(d) << d.message << '\n';
    if (showSourceLine_) {
      std::string_view line = d.loc.file->lineText(lc.line);
      size_t caret = lc.col - 1;
      if (caret > line.size())
        caret = line.size();
      if (line.size() > kMaxShownLine) {
        size_t from = caret > kMaxShownLine / 2 ? caret - kMaxShownLine / 2 : 0;
        line = line.substr(from, kMaxShownLine);
        caret -= from;
      }
      os_ << line << '\n';
      for (size_t i = 0; i < caret; ++i)
        os_ << (line[i] == '\t' ? '\t' : ' ');
      os_ << "^\n";
    }
  } else {
    os_ << severityName(d.severity) << ": " << subjectPrefix(d) << d.message << '\n';
  }
  for (const Diagnostic &n : d.notes)
    print(n);
}

void TextDiagnosticPrinter::handle(const Diagnostic &d) {
  print(d);
  os_.flush();
}

namespace {

void writeJsonDiagnostic(json::Writer &w, const Diagnostic &d) {
  w.beginObject();
  w.key("severity").value(severityName(d.severity));
  if (d.loc.valid()) {
    LineCol lc = d.loc.file->lineCol(d.loc.offset);
    w.key("file").value(d.loc.file->name());
    w.key("line").value(static_cast<uint64_t>(lc.line));
    w.key("column").value(static_cast<uint64_t>(lc.col));
  }
  if (d.entityId != 0) {
    w.key("entity_id").value(d.entityId);
    if (!d.entityName.empty())
      w.key("entity").value(d.entityName);
  }
  w.key("message").value(d.message);
  if (!d.notes.empty()) {
    w.key("notes").beginArray();
    for (const Diagnostic &n : d.notes)
      writeJsonDiagnostic(w, n);
    w.endArray();
  }
  w.endObject();
}

} // namespace

void JsonDiagnosticPrinter::handle(const Diagnostic &d) {
  os_ << (first_ ? "[\n  " : ",\n  ");
  first_ = false;
  json::Writer w(os_);
  writeJsonDiagnostic(w, d);
}

void JsonDiagnosticPrinter::finish() {
  if (finished_)
    return;
  finished_ = true;
  os_ << (first_ ? "[]\n" : "\n]\n");
  os_.flush();
}

InFlightDiagnostic::~InFlightDiagnostic() {
  if (engine_)
    engine_->emit(std::move(diag_));
}

InFlightDiagnostic &InFlightDiagnostic::entity(uint64_t id, std::string name) {
  diag_.entityId = id;
  diag_.entityName = std::move(name);
  return *this;
}

InFlightDiagnostic &InFlightDiagnostic::note(SourceLoc loc, std::string message) {
  Diagnostic n;
  n.severity = Severity::Note;
  n.loc = loc;
  n.message = std::move(message);
  diag_.notes.push_back(std::move(n));
  return *this;
}

InFlightDiagnostic DiagnosticEngine::report(Severity severity, SourceLoc loc, std::string message) {
  Diagnostic d;
  d.severity = severity;
  d.loc = loc;
  d.message = std::move(message);
  return InFlightDiagnostic(this, std::move(d));
}

InFlightDiagnostic DiagnosticEngine::assumption(SourceLoc loc, std::string message) {
  if (strict_)
    return error(loc, std::move(message));
  return warning(loc, message + "; --strict makes it an error");
}

void DiagnosticEngine::emit(Diagnostic &&d) {
  if (d.severity == Severity::Warning && warningsAsErrors_)
    d.severity = Severity::Error;
  if (limitReached_ && d.severity != Severity::Remark)
    return;
  if (d.severity == Severity::Error) {
    ++errors_;
  } else if (d.severity == Severity::Warning) {
    ++warnings_;
  }
  consumer_->handle(d);
  if (d.severity == Severity::Error && maxErrors_ != 0 && errors_ >= maxErrors_) {
    limitReached_ = true;
    Diagnostic stop;
    stop.severity = Severity::Note;
    stop.message = "too many errors (" + std::to_string(errors_) +
                   "), stopping now; --max-errors=0 shows all";
    consumer_->handle(stop);
  }
}

} // namespace stepnc
