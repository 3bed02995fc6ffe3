// The diagnostics engine every layer reports through.
//
// A diagnostic has a severity, a source location, an optional subject (the Part 21
// entity it is about: "#12 CARTESIAN_POINT"), a message and attached notes that
// point at related places. Consumers render them: as text in the compiler style
// `file:line:col: error: message` with the source line and a caret, or as JSON.
// The engine counts errors and stops accepting them after a limit, so a reader
// can collect many errors and still stop early on hopeless input.
#pragma once

#include "support/SourceFile.h"

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace stepnc {

enum class Severity : uint8_t { Error, Warning, Note, Remark };

const char *severityName(Severity s);

struct Diagnostic {
  Severity severity = Severity::Error;
  SourceLoc loc;
  /// The Part 21 instance the diagnostic is about; 0 when none.
  uint64_t entityId = 0;
  /// Its entity type name, when known.
  std::string entityName;
  std::string message;
  std::vector<Diagnostic> notes;
};

/// Receives finished diagnostics.
class DiagnosticConsumer {
public:
  virtual ~DiagnosticConsumer() = default;
  virtual void handle(const Diagnostic &diag) = 0;
  /// Called once when no more diagnostics will come (e.g. to close a JSON array).
  virtual void finish() {}
};

/// `file:line:col: error: #12 CARTESIAN_POINT: message`, source line, caret, notes.
class TextDiagnosticPrinter final : public DiagnosticConsumer {
public:
  explicit TextDiagnosticPrinter(std::ostream &os, bool showSourceLine = true)
      : os_(os), showSourceLine_(showSourceLine) {}
  void handle(const Diagnostic &diag) override;

private:
  void print(const Diagnostic &diag);
  std::ostream &os_;
  bool showSourceLine_;
};

/// A JSON array of objects {severity, file, line, column, entity_id, entity,
/// message, notes[]}, written when finish() is called.
class JsonDiagnosticPrinter final : public DiagnosticConsumer {
public:
  explicit JsonDiagnosticPrinter(std::ostream &os) : os_(os) {}
  void handle(const Diagnostic &diag) override;
  void finish() override;

private:
  std::ostream &os_;
  bool first_ = true;
  bool finished_ = false;
};

/// Collects diagnostics in memory (for tests and for callers that sort them).
class DiagnosticCollector final : public DiagnosticConsumer {
public:
  void handle(const Diagnostic &diag) override { diags.push_back(diag); }
  std::vector<Diagnostic> diags;
};

class DiagnosticEngine;

/// A diagnostic being built; it is reported when this object goes out of scope.
class InFlightDiagnostic {
public:
  InFlightDiagnostic(DiagnosticEngine *engine, Diagnostic diag)
      : engine_(engine), diag_(std::move(diag)) {}
  InFlightDiagnostic(InFlightDiagnostic &&other) noexcept
      : engine_(other.engine_), diag_(std::move(other.diag_)) {
    other.engine_ = nullptr;
  }
  InFlightDiagnostic(const InFlightDiagnostic &) = delete;
  InFlightDiagnostic &operator=(const InFlightDiagnostic &) = delete;
  InFlightDiagnostic &operator=(InFlightDiagnostic &&) = delete;
  ~InFlightDiagnostic();

  /// Names the Part 21 instance the diagnostic is about.
  InFlightDiagnostic &entity(uint64_t id, std::string name = {});
  InFlightDiagnostic &note(SourceLoc loc, std::string message);
  InFlightDiagnostic &note(std::string message) { return note(SourceLoc{}, std::move(message)); }

private:
  DiagnosticEngine *engine_;
  Diagnostic diag_;
};

class DiagnosticEngine {
public:
  explicit DiagnosticEngine(DiagnosticConsumer &consumer) : consumer_(&consumer) {}

  InFlightDiagnostic report(Severity severity, SourceLoc loc, std::string message);
  InFlightDiagnostic error(SourceLoc loc, std::string message) {
    return report(Severity::Error, loc, std::move(message));
  }
  InFlightDiagnostic warning(SourceLoc loc, std::string message) {
    return report(Severity::Warning, loc, std::move(message));
  }
  InFlightDiagnostic remark(SourceLoc loc, std::string message) {
    return report(Severity::Remark, loc, std::move(message));
  }
  /// What stepnc assumes to get past an imperfect input: a warning that says
  /// what was assumed (the message names the value), an error under strict
  /// mode. The message gains "; --strict makes it an error" when it is a
  /// warning.
  InFlightDiagnostic assumption(SourceLoc loc, std::string message);

  /// Errors after this many are dropped and limitReached() turns true; 0 means no limit.
  void setMaxErrors(unsigned n) { maxErrors_ = n; }
  /// Warnings become errors.
  void setWarningsAsErrors(bool on) { warningsAsErrors_ = on; }
  /// Assumptions become errors (--strict).
  void setStrict(bool on) { strict_ = on; }
  bool strict() const { return strict_; }
  bool limitReached() const { return limitReached_; }

  unsigned errorCount() const { return errors_; }
  unsigned warningCount() const { return warnings_; }
  bool hasErrors() const { return errors_ > 0; }
  void resetCounts() { errors_ = warnings_ = 0; limitReached_ = false; }

  void finish() { consumer_->finish(); }

private:
  friend class InFlightDiagnostic;
  void emit(Diagnostic &&diag);

  DiagnosticConsumer *consumer_;
  unsigned maxErrors_ = 0;
  unsigned errors_ = 0;
  unsigned warnings_ = 0;
  bool limitReached_ = false;
  bool warningsAsErrors_ = false;
  bool strict_ = false;
};

} // namespace stepnc
