// The Part 21 structure reader and instance-table scanner.
//
// One pass over the file: sections are recognised by keyword, header entities,
// DATA parameters and ed. 3 ANCHOR / REFERENCE entries are decoded eagerly, and
// each data instance is only delimited: its id and entity name are read, then
// the scanner jumps to the terminating ';' skipping strings and comments with
// memchr and tracking parentheses (so a missing ';' is caught at the ')' that
// closes the instance, not many instances later). The hot loop touches each byte
// once and branches only on the few bytes that matter.
#include "support/Format.h"
#include "frontend/part21/Decoder.h"
#include "frontend/part21/Lexing.h"
#include "frontend/part21/Part21File.h"

#include <algorithm>
#include <cstring>
#include <sys/mman.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace stepnc::p21 {

using namespace lex;

namespace {

// Bytes the body scanner must look at; everything else is skipped.
enum BodyClass : uint8_t { kPlain = 0, kQuote, kSemicolon, kSlash, kOpen, kClose, kNul };

struct BodyTable {
  uint8_t cls[256] = {};
  constexpr BodyTable() {
    cls[static_cast<uint8_t>('\'')] = kQuote;
    cls[static_cast<uint8_t>(';')] = kSemicolon;
    cls[static_cast<uint8_t>('/')] = kSlash;
    cls[static_cast<uint8_t>('(')] = kOpen;
    cls[static_cast<uint8_t>(')')] = kClose;
    cls[0] = kNul;
  }
};
constexpr BodyTable kBody;

bool startsWithKeyword(const char *p, const char *end, std::string_view kw) {
  if (static_cast<size_t>(end - p) < kw.size() || std::memcmp(p, kw.data(), kw.size()) != 0)
    return false;
  const char *after = p + kw.size();
  return after == end || !(isKeywordChar(*after) || *after == '-');
}

} // namespace

class Reader {
public:
  Reader(Part21File &file, DiagnosticEngine &diags)
      : file_(file), diags_(diags), base_(file.source().begin()), p_(base_),
        end_(file.source().end()) {}

  void run();

private:
  uint64_t off(const char *q) const { return static_cast<uint64_t>(q - base_); }
  SourceLoc loc(const char *q) const { return file_.loc(off(q)); }

  bool layout();
  bool expectSemicolon(const char *what);
  void skipStatement();
  std::string_view readKeyword();

  void parseHeader(const char *sectionStart);
  void checkHeader(const char *sectionStart);
  void reserveEntries();
  void parseData(const char *sectionStart);
  void parseAnchor();
  void parseReference();
  void skipSignature(const char *sectionStart);
  bool scanInstance();
  const char *scanBody(const char *q, const char *instanceStart);
  bool atSectionEnd(const char *sectionStart, const char *sectionName);

  Part21File &file_;
  DiagnosticEngine &diags_;
  const char *base_;
  const char *p_;
  const char *end_;
  bool fatal_ = false;  // input ended inside a token: stop without cascading errors
  bool warnedLowercase_ = false;
};

bool Reader::layout() {
  if (skipLayout(p_, end_) == Layout::UnterminatedComment) {
    diags_.error(loc(p_), "unterminated comment: '/*' has no matching '*/'");
    p_ = end_;
    fatal_ = true;
    return false;
  }
  return true;
}

std::string_view Reader::readKeyword() {
  const char *s = p_;
  if (p_ < end_ && *p_ == '!')
    ++p_;
  while (p_ < end_ && (isKeywordChar(*p_) || *p_ == '-'))
    ++p_;
  return {s, static_cast<size_t>(p_ - s)};
}

bool Reader::expectSemicolon(const char *what) {
  if (!layout())
    return false;
  if (p_ < end_ && *p_ == ';') {
    ++p_;
    return true;
  }
  diags_.error(loc(p_), std::string("expected ';' after ") + what);
  return false;
}

// Error recovery: continue after the next ';' outside strings and comments.
void Reader::skipStatement() {
  while (p_ < end_) {
    char c = *p_;
    if (c == ';') {
      ++p_;
      return;
    }
    if (c == '\'') {
      const void *q = std::memchr(p_ + 1, '\'', static_cast<size_t>(end_ - p_ - 1));
      p_ = q ? static_cast<const char *>(q) + 1 : end_;
      continue;
    }
    if (c == '/' && p_ + 1 < end_ && p_[1] == '*') {
      if (!layout())
        return;
      continue;
    }
    ++p_;
  }
}

void Reader::run() {
  if (static_cast<uint64_t>(end_ - base_) > InstanceEntry::kMaxBegin) {
    diags_.error(loc(base_), "files larger than 1 TiB are not supported");
    return;
  }
  // Editors on Windows often start UTF-8 files with a byte order mark.
  if (end_ - p_ >= 3 && static_cast<unsigned char>(p_[0]) == 0xEF && static_cast<unsigned char>(p_[1]) == 0xBB &&
      static_cast<unsigned char>(p_[2]) == 0xBF) {
    diags_.warning(loc(p_), "UTF-8 byte order mark at the start of the file ignored");
    p_ += 3;
  }
  if (!layout())
    return;
  if (p_ == end_) {
    diags_.error(loc(p_), "empty file: expected 'ISO-10303-21;'");
    return;
  }
  if (!startsWithKeyword(p_, end_, "ISO-10303-21")) {
    diags_.error(loc(p_), "not a Part 21 file: expected 'ISO-10303-21;' at the start");
    return;
  }
  p_ += 12;
  expectSemicolon("'ISO-10303-21'");

  bool sawHeader = false, sawData = false;
  for (;;) {
    if (!layout() || fatal_)
      return;
    if (p_ == end_) {
      diags_.error(loc(p_), "missing 'END-ISO-10303-21;' at end of file");
      return;
    }
    const char *kwStart = p_;
    std::string_view kw = readKeyword();
    if (kw == "HEADER") {
      if (sawHeader)
        diags_.error(loc(kwStart), "second HEADER section");
      sawHeader = true;
      if (expectSemicolon("'HEADER'"))
        parseHeader(kwStart);
      checkHeader(kwStart);
    } else if (kw == "DATA") {
      if (!sawHeader && !sawData)
        diags_.error(loc(kwStart), "DATA section before the HEADER section");
      sawData = true;
      parseData(kwStart);
    } else if (kw == "ANCHOR") {
      if (expectSemicolon("'ANCHOR'"))
        parseAnchor();
    } else if (kw == "REFERENCE") {
      if (expectSemicolon("'REFERENCE'"))
        parseReference();
    } else if (kw == "SIGNATURE") {
      skipSignature(kwStart);
    } else if (kw == "END-ISO-10303-21") {
      expectSemicolon("'END-ISO-10303-21'");
      if (!sawHeader)
        diags_.error(loc(kwStart), "file has no HEADER section");
      if (layout() && p_ != end_)
        diags_.warning(loc(p_), "text after 'END-ISO-10303-21;' is ignored");
      return;
    } else if (kw == "ENDSEC") {
      diags_.error(loc(kwStart), "'ENDSEC' outside of a section");
      skipStatement();
    } else {
      if (kw.empty())
        diags_.error(loc(kwStart), "expected a section keyword (HEADER, DATA, ANCHOR, "
                                   "REFERENCE, SIGNATURE or END-ISO-10303-21)");
      else
        diags_.error(loc(kwStart), "unknown section keyword '" + std::string(kw) + "'");
      p_ = kwStart;
      skipStatement();
    }
    if (diags_.limitReached())
      return;
  }
}

// True (and consumes "ENDSEC;") at the end of a section; reports a missing
// ENDSEC when the file or the next section starts instead.
bool Reader::atSectionEnd(const char *sectionStart, const char *sectionName) {
  if (p_ == end_) {
    if (!fatal_)
      diags_.error(loc(p_), std::string("missing 'ENDSEC;' at end of file"))
          .note(loc(sectionStart), std::string(sectionName) + " section starts here");
    fatal_ = true;
    return true;
  }
  if (startsWithKeyword(p_, end_, "ENDSEC")) {
    p_ += 6;
    expectSemicolon("'ENDSEC'");
    return true;
  }
  for (const char *kw : {"END-ISO-10303-21", "DATA", "HEADER", "ANCHOR", "REFERENCE", "SIGNATURE"}) {
    if (startsWithKeyword(p_, end_, kw)) {
      diags_.error(loc(p_), std::string("missing 'ENDSEC;' before '") + kw + "'")
          .note(loc(sectionStart), std::string(sectionName) + " section starts here");
      return true;
    }
  }
  return false;
}

void Reader::parseHeader(const char *sectionStart) {
  ValueArena &arena = file_.metadata_;
  for (;;) {
    if (!layout() || atSectionEnd(sectionStart, "HEADER"))
      return;
    const char *start = p_;
    Decoder dec(file_, arena, &diags_, base_, 0, "header");
    Record rec;
    const char *after = dec.parseRecord(p_, end_, rec);
    if (!after) {
      p_ = start;
      skipStatement();
      continue;
    }
    p_ = after;
    if (!expectSemicolon("header entity")) {
      skipStatement();
      continue;
    }
    file_.header_.push_back({rec, off(start)});
  }
}

void Reader::checkHeader(const char *sectionStart) {
  for (const char *required : {"FILE_DESCRIPTION", "FILE_NAME", "FILE_SCHEMA"})
    if (!file_.headerEntity(required))
      diags_.warning(loc(sectionStart), std::string("header has no ") + required + " entity");
}

// Reserves the instance table for the rest of the file (instances are rarely
// shorter than 32 bytes), so it is never copied while growing; pages never
// written cost no memory. Huge pages cut the page faults of filling it.
void Reader::reserveEntries() {
  auto &entries = file_.entries_;
  const size_t estimate = entries.size() + static_cast<size_t>(end_ - p_) / 32 + 16;
  if (estimate <= entries.capacity())
    return;
  entries.reserve(estimate);
  const size_t bytes = entries.capacity() * sizeof(InstanceEntry);
  if (bytes >= (size_t{4} << 20)) {
    const auto page = uintptr_t{2} << 20;
    const auto from = (reinterpret_cast<uintptr_t>(entries.data()) + page - 1) & ~(page - 1);
    const auto to = (reinterpret_cast<uintptr_t>(entries.data()) + bytes) & ~(page - 1);
    if (to > from)
      ::madvise(reinterpret_cast<void *>(from), to - from, MADV_HUGEPAGE);
  }
}

void Reader::parseData(const char *sectionStart) {
  DataSection section;
  section.begin = off(sectionStart);
  if (!layout())
    return;
  if (p_ < end_ && *p_ == '(') {
    // Ed. 3: DATA('name', ('SCHEMA', ...));
    Decoder dec(file_, file_.metadata_, &diags_, base_, 0, "DATA");
    std::vector<Value> params;
    const char *after = dec.parseParamList(p_, end_, params);
    if (!after) {
      skipStatement();
    } else {
      p_ = after;
      section.params = std::move(params);
      expectSemicolon("DATA parameters");
    }
  } else if (!expectSemicolon("'DATA'")) {
    skipStatement();
  }
  reserveEntries();
  section.firstEntry = static_cast<uint32_t>(file_.entries_.size());
  for (;;) {
    if (!layout() || fatal_)
      break;
    if (p_ < end_ && *p_ == '#') {
      if (!scanInstance())
        skipStatement();
      if (diags_.limitReached())
        break;
      continue;
    }
    if (atSectionEnd(sectionStart, "DATA"))
      break;
    if (static_cast<unsigned char>(*p_) >= 0x80)
      diags_.error(loc(p_), "non-ASCII byte outside a string");
    else
      diags_.error(loc(p_), "expected an instance '#id=...;' or 'ENDSEC;'");
    skipStatement();
  }
  section.endEntry = static_cast<uint32_t>(file_.entries_.size());
  file_.sections_.push_back(std::move(section));
}

// Delimits one `#id = NAME(...);` or `#id = (A(...)B(...));` starting at '#'.
bool Reader::scanInstance() {
  const char *start = p_;
  const char *q = p_ + 1;
  if (q >= end_ || !isDigit(*q)) {
    diags_.error(loc(q), "expected an instance id (digits) after '#'");
    return false;
  }
  uint64_t id = 0;
  const char *digits = q;
  while (q < end_ && isDigit(*q)) {
    if (id > (UINT64_MAX - 9) / 10) {
      diags_.error(loc(digits), "instance id is too large");
      return false;
    }
    id = id * 10 + static_cast<uint64_t>(*q - '0');
    ++q;
  }
  p_ = q;
  if (*p_ != '=') {
    if (!layout())
      return false;
    if (p_ >= end_ || *p_ != '=') {
      diags_.error(loc(p_), "expected '=' after " + hashId(id));
      return false;
    }
  }
  ++p_;
  if (p_ < end_ && !isKeywordStart(*p_) && *p_ != '(' && !layout())
    return false;
  NameId name;
  if (p_ < end_ && *p_ == '(') {
    name = kComplexInstance;
  } else if (p_ < end_ && isKeywordStart(*p_)) {
    const char *n = p_;
    if (*p_ == '!') {
      ++p_;
      if (p_ >= end_ || !isKeywordStart(*p_) || *p_ == '!') {
        diags_.error(loc(n), "expected a user-defined entity name after '!'");
        return false;
      }
    }
    uint8_t classes = 0;
    while (p_ < end_ && isKeywordChar(*p_))
      classes |= classOf(*p_++);
    const std::string_view text(n, static_cast<size_t>(p_ - n));
    if (classes & kLower) {
      if (!warnedLowercase_) {
        warnedLowercase_ = true;
        diags_.warning(loc(n), "entity name '" + std::string(text) +
                                   "' has lower-case letters; Part 21 keywords are upper case "
                                   "(read as upper case; further cases not reported)");
      }
      name = file_.names_.intern(text);
    } else {
      name = file_.names_.internUpper(text);
    }
    if (name >= InstanceEntry::kMaxNames) {
      diags_.error(loc(n), "more than 16 million distinct entity names");
      fatal_ = true;
      return false;
    }
  } else {
    if (p_ < end_ && static_cast<unsigned char>(*p_) >= 0x80)
      diags_.error(loc(p_), "non-ASCII byte outside a string");
    else
      diags_.error(loc(p_), "expected an entity name or '(' after '" + hashId(id) + "='");
    return false;
  }
  const char *stop = scanBody(p_, start);
  if (!stop)
    return false;
  file_.entries_.emplace_back(id, off(start), name);
  p_ = stop;
  return true;
}

// Finds the end of an instance body starting at `q` (just after the name, or
// at '(' for a complex instance). Returns the position after the ';', or after
// the closing ')' when the ';' is missing (reported), or null at end of file.
// Skips bytes the body scanner need not look at. SSE2 compares 16 bytes at a
// time against the six bytes that matter; loads never pass `end`, so this is
// also clean under AddressSanitizer on heap-backed sources.
inline const char *skipPlain(const char *q, const char *end) {
#if defined(__SSE2__)
  const __m128i quote = _mm_set1_epi8('\'');
  const __m128i semi = _mm_set1_epi8(';');
  const __m128i slash = _mm_set1_epi8('/');
  const __m128i open = _mm_set1_epi8('(');
  const __m128i close = _mm_set1_epi8(')');
  const __m128i nul = _mm_setzero_si128();
  while (end - q >= 16) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i *>(q));
    const __m128i hit = _mm_or_si128(
        _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi8(v, quote), _mm_cmpeq_epi8(v, semi)),
                     _mm_or_si128(_mm_cmpeq_epi8(v, slash), _mm_cmpeq_epi8(v, open))),
        _mm_or_si128(_mm_cmpeq_epi8(v, close), _mm_cmpeq_epi8(v, nul)));
    const int mask = _mm_movemask_epi8(hit);
    if (mask)
      return q + __builtin_ctz(static_cast<unsigned>(mask));
    q += 16;
  }
#else
  (void)end;
#endif
  while (kBody.cls[static_cast<uint8_t>(*q)] == kPlain)
    ++q;
  return q;
}

const char *Reader::scanBody(const char *q, const char *instanceStart) {
  int depth = 0;
  for (;;) {
    q = skipPlain(q, end_);
    switch (kBody.cls[static_cast<uint8_t>(*q)]) {
    case kSemicolon:
      return q + 1;
    case kOpen:
      ++depth;
      ++q;
      break;
    case kClose:
      ++q;
      if (--depth == 0) {
        // The instance's parameter list is closed: only ';' may follow.
        const char *r = q;
        if (skipLayout(r, end_) == Layout::Ok && r < end_ && *r != ';') {
          diags_.error(loc(q), "expected ';' at end of instance")
              .note(loc(instanceStart), "instance starts here");
          return q;
        }
      }
      break;
    case kQuote: {
      const void *close = std::memchr(q + 1, '\'', static_cast<size_t>(end_ - q - 1));
      if (!close) {
        diags_.error(loc(q), "unterminated string: no closing quote before end of file")
            .note(loc(instanceStart), "in this instance");
        fatal_ = true;
        return nullptr;
      }
      q = static_cast<const char *>(close) + 1;
      break;
    }
    case kSlash:
      if (q[1] == '*') {
        const char *r = q;
        if (skipLayout(r, end_) == Layout::UnterminatedComment) {
          diags_.error(loc(q), "unterminated comment: '/*' has no matching '*/'");
          fatal_ = true;
          return nullptr;
        }
        q = r;
      } else {
        ++q;
      }
      break;
    case kNul:
      if (q >= end_) {
        diags_.error(loc(instanceStart), "instance is not terminated: no ';' before end of file");
        fatal_ = true;
        return nullptr;
      }
      ++q;  // a NUL byte inside the file: the decoder reports it
      break;
    }
  }
}

void Reader::parseAnchor() {
  const char *sectionStart = p_;
  for (;;) {
    if (!layout() || atSectionEnd(sectionStart, "ANCHOR"))
      return;
    const char *start = p_;
    if (*p_ != '<') {
      diags_.error(loc(p_), "expected an anchor '<name>=value;' or 'ENDSEC;'");
      skipStatement();
      continue;
    }
    const char *close = static_cast<const char *>(std::memchr(p_, '>', static_cast<size_t>(end_ - p_)));
    if (!close) {
      diags_.error(loc(p_), "unterminated anchor name: no '>'");
      p_ = end_;
      return;
    }
    Anchor anchor;
    anchor.name.assign(p_ + 1, close);
    anchor.begin = off(start);
    p_ = close + 1;
    if (!layout() || p_ >= end_ || *p_ != '=') {
      diags_.error(loc(p_), "expected '=' after anchor name");
      skipStatement();
      continue;
    }
    ++p_;
    if (!layout())
      return;
    Decoder dec(file_, file_.metadata_, &diags_, base_, 0, "ANCHOR");
    std::vector<Value> one;
    const char *after = dec.parseSingleParam(p_, end_, anchor.value);
    if (!after) {
      skipStatement();
      continue;
    }
    p_ = after;
    // Optional ed. 3 anchor tags `{ ... }` are skipped.
    if (layout() && p_ < end_ && *p_ == '{') {
      while (p_ < end_ && *p_ != ';')
        ++p_;
    }
    if (expectSemicolon("anchor"))
      file_.anchors_.push_back(std::move(anchor));
    else
      skipStatement();
  }
}

void Reader::parseReference() {
  const char *sectionStart = p_;
  for (;;) {
    if (!layout() || atSectionEnd(sectionStart, "REFERENCE"))
      return;
    const char *start = p_;
    if (*p_ != '#' || p_ + 1 >= end_ || !isDigit(p_[1])) {
      diags_.warning(loc(p_), "REFERENCE entry not of the form '#id=<uri>;' skipped");
      skipStatement();
      continue;
    }
    ++p_;
    const char *digits = p_;
    uint64_t id = 0;
    bool overflow = false;
    while (p_ < end_ && isDigit(*p_)) {
      overflow |= id > (UINT64_MAX - 9) / 10;
      id = id * 10 + static_cast<uint64_t>(*p_++ - '0');
    }
    if (overflow) {
      diags_.error(loc(digits), "instance id is too large");
      skipStatement();
      continue;
    }
    if (!layout() || p_ >= end_ || *p_ != '=') {
      diags_.error(loc(p_), "expected '=' in REFERENCE entry");
      skipStatement();
      continue;
    }
    ++p_;
    if (!layout())
      return;
    if (p_ >= end_ || *p_ != '<') {
      diags_.error(loc(p_), "expected '<uri>' in REFERENCE entry");
      skipStatement();
      continue;
    }
    const char *close = static_cast<const char *>(std::memchr(p_, '>', static_cast<size_t>(end_ - p_)));
    if (!close) {
      diags_.error(loc(p_), "unterminated URI: no '>'");
      p_ = end_;
      return;
    }
    ExternalReference ref{id, std::string(p_ + 1, close), off(start)};
    p_ = close + 1;
    if (expectSemicolon("REFERENCE entry"))
      file_.references_.push_back(std::move(ref));
    else
      skipStatement();
  }
}

void Reader::skipSignature(const char *sectionStart) {
  diags_.warning(loc(sectionStart), "SIGNATURE section is not checked and is not kept");
  const char *q = p_;
  while (q < end_) {
    if (*q == 'E' && startsWithKeyword(q, end_, "ENDSEC")) {
      p_ = q + 6;
      expectSemicolon("'ENDSEC'");
      return;
    }
    ++q;
  }
  p_ = end_;
  diags_.error(loc(p_), "missing 'ENDSEC;' at end of file")
      .note(loc(sectionStart), "SIGNATURE section starts here");
  fatal_ = true;
}

void IdIndex::build(const std::vector<InstanceEntry> &entries,
                    const std::function<void(uint32_t, uint32_t)> &duplicate) {
  *this = IdIndex();
  const size_t n = entries.size();
  bool ascending = true;
  for (size_t i = 0; i < n; ++i) {
    maxId_ = std::max(maxId_, entries[i].id);
    if (i > 0 && entries[i].id <= entries[i - 1].id)
      ascending = false;
  }
  if (maxId_ > 64 * static_cast<uint64_t>(n) + 65536) {
    // Very sparse ids: sorted (id, entry) pairs.
    sparse_.reserve(n);
    for (uint32_t i = 0; i < n; ++i)
      sparse_.emplace_back(entries[i].id, i);
    std::stable_sort(sparse_.begin(), sparse_.end(),
                     [](const auto &a, const auto &b) { return a.first < b.first; });
    size_t out = 0;
    for (size_t i = 0; i < sparse_.size(); ++i) {
      if (out > 0 && sparse_[out - 1].first == sparse_[i].first) {
        duplicate(sparse_[out - 1].second, sparse_[i].second);
        continue;
      }
      sparse_[out++] = sparse_[i];
    }
    sparse_.resize(out);
    return;
  }
  const size_t words = static_cast<size_t>(maxId_ >> 6) + 1;
  bits_.assign(words, 0);
  for (const InstanceEntry &e : entries)
    bits_[static_cast<size_t>(e.id >> 6)] |= uint64_t{1} << (e.id & 63);
  ranks_.resize(words);
  uint32_t rank = 0;
  for (size_t w = 0; w < words; ++w) {
    ranks_[w] = rank;
    rank += static_cast<uint32_t>(__builtin_popcountll(bits_[w]));
  }
  if (ascending)
    return;  // entry index == rank
  order_.assign(rank, UINT32_MAX);
  for (uint32_t i = 0; i < n; ++i) {
    const InstanceId id = entries[i].id;
    const uint64_t word = bits_[static_cast<size_t>(id >> 6)];
    const uint64_t bit = uint64_t{1} << (id & 63);
    const uint32_t r = ranks_[static_cast<size_t>(id >> 6)] +
                       static_cast<uint32_t>(__builtin_popcountll(word & (bit - 1)));
    if (order_[r] != UINT32_MAX)
      duplicate(order_[r], i);
    else
      order_[r] = i;
  }
}

int64_t IdIndex::findSparse(InstanceId id) const {
  auto it = std::lower_bound(sparse_.begin(), sparse_.end(), id,
                             [](const auto &p, InstanceId v) { return p.first < v; });
  if (it == sparse_.end() || it->first != id)
    return -1;
  return it->second;
}

void Part21File::buildIndex(DiagnosticEngine &diags) {
  index_.build(entries_, [&](uint32_t first, uint32_t second) {
    const InstanceEntry &a = entries_[first];
    const InstanceEntry &b = entries_[second];
    diags.error(loc(b.begin()), "duplicate instance id " + hashId(b.id))
        .entity(b.id, std::string(entityName(b)))
        .note(loc(a.begin()), hashId(a.id) + " first defined here");
  });
}

bool Part21File::isDefined(InstanceId id) const {
  if (indexOf(id) >= 0)
    return true;
  return std::binary_search(referenceIds_.begin(), referenceIds_.end(), id);
}

std::unique_ptr<Part21File> readPart21(const SourceFile &source, DiagnosticEngine &diags,
                                       const ReadOptions &options) {
  auto file = std::make_unique<Part21File>();
  file->source_ = &source;
  file->options_ = options;
  Reader reader(*file, diags);
  reader.run();
  file->buildIndex(diags);
  for (const ExternalReference &r : file->references_)
    file->referenceIds_.push_back(r.id);
  std::sort(file->referenceIds_.begin(), file->referenceIds_.end());
  return file;
}

} // namespace stepnc::p21
