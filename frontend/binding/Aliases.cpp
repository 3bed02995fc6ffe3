#include "frontend/binding/Aliases.h"

#include "frontend/express/Schema.h"

#include <cstdlib>
#include <iostream>

namespace stepnc::embedded {
extern const char aliases_txt[];
extern const unsigned long aliases_txt_size;
} // namespace stepnc::embedded

namespace stepnc::binding {

bool AliasTable::parse(std::string_view text, std::string &error) {
  size_t lineNo = 0;
  while (!text.empty()) {
    size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
    ++lineNo;
    if (size_t hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    std::string words[3];
    size_t n = 0;
    for (size_t i = 0; i < line.size();) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r'))
        ++i;
      size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r')
        ++i;
      if (i > start) {
        if (n == 3) {
          error = "line " + std::to_string(lineNo) + ": expected 'entity ALIAS schema_name'";
          return false;
        }
        words[n++] = std::string(line.substr(start, i - start));
      }
    }
    if (n == 0)
      continue;
    if (n != 3 || words[0] != "entity") {
      error = "line " + std::to_string(lineNo) + ": expected 'entity ALIAS schema_name'";
      return false;
    }
    std::string alias = words[1];
    for (char &c : alias)
      if (c >= 'a' && c <= 'z')
        c = static_cast<char>(c - 32);
    entities_[alias] = express::lower(words[2]);
  }
  return true;
}

std::string_view AliasTable::entity(std::string_view name) const {
  auto it = entities_.find(std::string(name));
  return it == entities_.end() ? std::string_view() : std::string_view(it->second);
}

const AliasTable &AliasTable::builtin() {
  static const AliasTable table = [] {
    AliasTable t;
    std::string error;
    if (!t.parse({embedded::aliases_txt, embedded::aliases_txt_size}, error)) {
      // The file is checked by the test suite; a broken build is a bug.
      std::cerr << "stepnc: internal error: built-in alias table: " << error << '\n';
      std::abort();
    }
    return t;
  }();
  return table;
}

} // namespace stepnc::binding
