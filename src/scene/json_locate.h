// scene/json_locate.h — owns source positions for JSON values.
// nlohmann::json 3.11 keeps no positions, yet every scene-file error must
// name its line. JsonLocator finds the line where the value at a JSON path
// ("objects[2].motion[1].translate") starts by scanning the original text:
// once when constructed (for what nlohmann silently accepts: duplicate keys,
// where nlohmann keeps the last one) and once per question (errors are
// rare; storing every path would cost memory quadratic in the depth).
// Every scan is iterative and linear in time and memory in the text's
// size. It also checks UTF-8 and nesting depth before parsing. No JSON
// library is involved, so tests and other modules may use it freely.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace tdpm::scene {

// Path helpers. The root is the empty path; members are appended as ".key"
// (bare "key" at the root) and array elements as "[i]".
std::string childPath(const std::string& parent, const std::string& key);
std::string elementPath(const std::string& parent, size_t index);
// The enclosing path ("a.b[2]" -> "a.b", "a" -> ""); "" for the root.
std::string parentPath(const std::string& path);
// How a path is shown to the user: the root reads "top level".
std::string displayPath(const std::string& path);

struct TextPosition {
  int line = 1;    // 1-based
  int column = 1;  // 1-based, in bytes
};
// Line and column of byte `offset` (0-based; clamped to the text).
TextPosition positionOf(const std::string& text, size_t offset);
// Offset of the first byte that is not part of well-formed UTF-8, or npos.
size_t firstInvalidUtf8(const std::string& text);

// Offset of the '[' or '{' that opens nesting level maxDepth + 1 (the root
// container is level 1; brackets inside strings do not count), or npos.
size_t firstTooDeep(const std::string& text, int maxDepth);

class JsonLocator {
 public:
  struct Duplicate {
    std::string path;  // the repeated member
    int line;          // where the repeat starts
  };

  // `text` should be syntactically valid JSON; on anything else the scans
  // stop early (best effort) instead of failing, so locating can never hide
  // the real error.
  explicit JsonLocator(const std::string& text);

  // Line where the value at `path` starts (the last one, if a key is
  // repeated). An unknown path (e.g. a missing key) falls back to its
  // nearest located ancestor, then to line 1.
  int line(const std::string& path) const;
  // The first member written twice in one object (empty if none): one is
  // enough for the error, and keeping all would not be linear in memory.
  const std::vector<Duplicate>& duplicates() const { return duplicates_; }
  // Path of the first number literal spelled exactly `token` ("1e999"), or
  // "" if none: nlohmann reports overflowing numbers by spelling alone.
  std::string findNumber(const std::string& token) const;

 private:
  std::string text_;  // a copy: line() and findNumber() scan it again later
  size_t start_ = 0;  // after a UTF-8 byte-order mark
  std::vector<Duplicate> duplicates_;
};

}  // namespace tdpm::scene
