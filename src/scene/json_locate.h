// scene/json_locate.h — owns source positions for JSON values.
// nlohmann::json 3.11 keeps no positions, yet every scene-file error must
// name its line. JsonLocator scans the original text once and maps each
// JSON path ("objects[2].motion[1].translate") to the line where its value
// starts. It also reports what nlohmann silently accepts (duplicate keys:
// nlohmann keeps the last one) and checks UTF-8 before parsing. No JSON
// library is involved, so tests and other modules may use it freely.
#pragma once
#include <cstddef>
#include <string>
#include <unordered_map>
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

class JsonLocator {
 public:
  struct Duplicate {
    std::string path;  // the repeated member
    int line;          // where the repeat starts
  };

  // `text` should be syntactically valid JSON; on anything else the scan
  // stops early (best effort) instead of failing, so locating can never hide
  // the real error.
  explicit JsonLocator(const std::string& text);

  // Line where the value at `path` starts. An unknown path (e.g. a missing
  // key) falls back to its nearest located ancestor, then to line 1.
  int line(const std::string& path) const;
  bool has(const std::string& path) const { return entries_.count(path) != 0; }
  // Members written twice in one object, in text order.
  const std::vector<Duplicate>& duplicates() const { return duplicates_; }
  // Path of the first number literal spelled exactly `token` ("1e999"), or
  // "" if none: nlohmann reports overflowing numbers by spelling alone.
  std::string findNumber(const std::string& token) const;

 private:
  struct Entry {
    int line;
    size_t offset;
  };
  struct Frame {
    bool isObject;
    std::string path;
    size_t count = 0;  // elements or members seen so far
    std::vector<std::string> keys;
  };

  void scan();
  bool beginValue(const std::string& path);
  bool nextInFrame();
  void skipWhitespace();
  bool readString(std::string* decoded);
  void skipScalar();

  std::string text_;  // a copy: findNumber() reads it after the scan
  size_t pos_ = 0;
  int line_ = 1;
  std::vector<Frame> stack_;
  std::unordered_map<std::string, Entry> entries_;
  std::vector<Duplicate> duplicates_;
};

}  // namespace tdpm::scene
