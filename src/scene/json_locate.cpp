// scene/json_locate.cpp — the JSON position scanner behind every located
// scene-file error (see json_locate.h). Iterative, not recursive, so a
// maliciously deep file cannot overflow the stack; it keeps one path string
// (appended and truncated as it walks), never one per value or per level.
#include "scene/json_locate.h"

#include <algorithm>
#include <unordered_set>

namespace tdpm::scene {

std::string childPath(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

std::string elementPath(const std::string& parent, size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

std::string parentPath(const std::string& path) {
  if (path.empty()) return path;
  if (path.back() == ']') {
    size_t open = path.rfind('[');
    return open == std::string::npos ? std::string() : path.substr(0, open);
  }
  // Keys may themselves contain '.', but a located ancestor is all we need.
  size_t cut = path.find_last_of(".]");
  if (cut == std::string::npos) return std::string();
  return path.substr(0, path[cut] == ']' ? cut + 1 : cut);
}

std::string displayPath(const std::string& path) { return path.empty() ? "top level" : path; }

TextPosition positionOf(const std::string& text, size_t offset) {
  offset = std::min(offset, text.size());
  TextPosition p;
  for (size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++p.line;
      p.column = 1;
    } else {
      ++p.column;
    }
  }
  return p;
}

size_t firstInvalidUtf8(const std::string& text) {
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  size_t n = text.size(), i = 0;
  while (i < n) {
    unsigned char c = s[i];
    size_t len;
    unsigned lo = 0x80, hi = 0xBF;  // allowed range of the second byte
    if (c < 0x80) { ++i; continue; }
    if (c >= 0xC2 && c <= 0xDF) len = 2;
    else if (c >= 0xE0 && c <= 0xEF) { len = 3; if (c == 0xE0) lo = 0xA0; if (c == 0xED) hi = 0x9F; }
    else if (c >= 0xF0 && c <= 0xF4) { len = 4; if (c == 0xF0) lo = 0x90; if (c == 0xF4) hi = 0x8F; }
    else return i;  // stray continuation byte, overlong lead or > U+10FFFF
    if (i + len > n) return i;
    if (s[i + 1] < lo || s[i + 1] > hi) return i;
    for (size_t k = 2; k < len; ++k)
      if (s[i + k] < 0x80 || s[i + k] > 0xBF) return i;
    i += len;
  }
  return std::string::npos;
}

size_t firstTooDeep(const std::string& text, int maxDepth) {
  int depth = 0;
  bool inString = false;
  for (size_t i = 0; i < text.size(); ++i) {
    char c = text[i];
    if (inString) {
      if (c == '\\') ++i;  // the escaped character cannot end the string
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > maxDepth) return i;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return std::string::npos;
}

namespace {

// Appends code point `cp` to `out` as UTF-8.
static void appendUtf8(std::string* out, unsigned cp) {
  if (cp < 0x80) {
    out->push_back(char(cp));
  } else if (cp < 0x800) {
    out->push_back(char(0xC0 | (cp >> 6)));
    out->push_back(char(0x80 | (cp & 0x3F)));
  } else if (cp < 0x10000) {
    out->push_back(char(0xE0 | (cp >> 12)));
    out->push_back(char(0x80 | ((cp >> 6) & 0x3F)));
    out->push_back(char(0x80 | (cp & 0x3F)));
  } else {
    out->push_back(char(0xF0 | (cp >> 18)));
    out->push_back(char(0x80 | ((cp >> 12) & 0x3F)));
    out->push_back(char(0x80 | ((cp >> 6) & 0x3F)));
    out->push_back(char(0x80 | (cp & 0x3F)));
  }
}

static bool readHex4(const std::string& t, size_t at, unsigned* v) {
  if (at + 4 > t.size()) return false;
  *v = 0;
  for (size_t i = at; i < at + 4; ++i) {
    char c = t[i];
    unsigned d = (c >= '0' && c <= '9') ? unsigned(c - '0')
                 : (c >= 'a' && c <= 'f') ? unsigned(c - 'a' + 10)
                 : (c >= 'A' && c <= 'F') ? unsigned(c - 'A' + 10) : 16u;
    if (d == 16) return false;
    *v = *v * 16 + d;
  }
  return true;
}

// One walk over the text, value by value, keeping the current value's JSON
// path in a single string. Calls visit(offset, line) at the start of every
// value (path() is its path); visit returns false to stop the walk.
class Walker {
 public:
  Walker(const std::string& text, size_t start) : t_(text), pos_(start) {}

  const std::string& path() const { return path_; }
  bool trackKeys = false;   // keep each object's keys (for duplicates)
  // With a target: `matched` tells whether path() is a prefix of *target
  // (component by component, so each byte of a path is compared once).
  const std::string* target = nullptr;
  bool matched = true;
  bool duplicate = false;   // the current member repeats a key of its object
  int keyLine = 0;          // line of the current member's key

  template <class Visit>
  void run(Visit&& visit) {
    matched = true;
    if (!beginValue(visit)) return;
    while (!stack_.empty())
      if (!next(visit)) return;
  }

 private:
  struct Frame {
    bool isObject;
    size_t count = 0;    // elements or members seen so far
    size_t pathLen = 0;  // length of the container's own path
    bool matched = true; // the container's path is a prefix of *target
    std::unordered_set<std::string> keys;
  };

  void skipWhitespace() {
    while (pos_ < t_.size()) {
      char c = t_[pos_];
      if (c == '\n') ++line_;
      else if (c != ' ' && c != '\t' && c != '\r') return;
      ++pos_;
    }
  }

  // Reads the string at pos_ (which is '"'), decoding escapes exactly as
  // nlohmann does, so that keys in paths match the parsed object's keys.
  bool readString(std::string* decoded) {
    ++pos_;
    while (pos_ < t_.size()) {
      char c = t_[pos_++];
      if (c == '"') return true;
      if (c != '\\') { if (decoded) decoded->push_back(c); continue; }
      if (pos_ >= t_.size()) return false;
      char e = t_[pos_++];
      unsigned cp = 0;
      switch (e) {
        case 'b': cp = '\b'; break;
        case 'f': cp = '\f'; break;
        case 'n': cp = '\n'; break;
        case 'r': cp = '\r'; break;
        case 't': cp = '\t'; break;
        case 'u': {
          if (!readHex4(t_, pos_, &cp)) return false;
          pos_ += 4;
          unsigned low = 0;  // a surrogate pair is one code point
          if (cp >= 0xD800 && cp <= 0xDBFF && t_.compare(pos_, 2, "\\u") == 0 && readHex4(t_, pos_ + 2, &low) &&
              low >= 0xDC00 && low <= 0xDFFF) {
            cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
            pos_ += 6;
          }
          break;
        }
        default: cp = static_cast<unsigned char>(e);  // \" \\ \/
      }
      if (decoded) appendUtf8(decoded, cp);
    }
    return false;
  }

  void skipScalar() {
    while (pos_ < t_.size()) {
      char c = t_[pos_];
      if (c == ',' || c == ']' || c == '}' || c == ' ' || c == '\t' || c == '\r' || c == '\n') return;
      ++pos_;
    }
  }

  // The value at pos_: visited, then entered if it is a container.
  template <class Visit>
  bool beginValue(Visit& visit) {
    skipWhitespace();
    if (pos_ >= t_.size()) return false;
    if (!visit(pos_, line_)) return false;
    char c = t_[pos_];
    if (c == '{' || c == '[') {
      ++pos_;
      stack_.push_back(Frame{c == '{', 0, path_.size(), matched, {}});
      return true;
    }
    if (c == '"') return readString(nullptr);
    skipScalar();
    return true;
  }

  // The next member/element of the innermost container, or its end.
  template <class Visit>
  bool next(Visit& visit) {
    skipWhitespace();
    if (pos_ >= t_.size()) return false;
    char c = t_[pos_];
    if (c == '}' || c == ']') {
      ++pos_;
      stack_.pop_back();
      return true;
    }
    if (c == ',') {
      ++pos_;
      skipWhitespace();
    }
    Frame& f = stack_.back();
    path_.resize(f.pathLen);
    duplicate = false;
    if (f.isObject) {
      keyLine = line_;
      key_.clear();
      if (pos_ >= t_.size() || t_[pos_] != '"' || !readString(&key_)) return false;
      skipWhitespace();
      if (pos_ >= t_.size() || t_[pos_] != ':') return false;
      ++pos_;
      if (!path_.empty()) path_ += '.';
      path_ += key_;
      if (trackKeys) duplicate = !f.keys.insert(key_).second;
    } else {
      path_ += '[';
      path_ += std::to_string(f.count);
      path_ += ']';
    }
    ++f.count;
    if (target) {
      size_t added = path_.size() - f.pathLen;
      matched = f.matched && path_.size() <= target->size() &&
                target->compare(f.pathLen, added, path_, f.pathLen, added) == 0;
    }
    return beginValue(visit);  // may push: f is not used afterwards
  }

  const std::string& t_;
  size_t pos_;
  int line_ = 1;
  std::string path_, key_;
  std::vector<Frame> stack_;
};

// nlohmann skips a UTF-8 byte-order mark; so do we.
size_t afterBom(const std::string& text) { return text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0; }

}  // namespace

JsonLocator::JsonLocator(const std::string& text) : text_(text), start_(afterBom(text_)) {
  Walker w(text_, start_);
  w.trackKeys = true;
  w.run([&](size_t, int) {
    if (!w.duplicate) return true;
    duplicates_.push_back({w.path(), w.keyLine});
    return false;
  });
}

int JsonLocator::line(const std::string& path) const {
  // The path and its ancestors are prefixes of `path`: follow, per level,
  // whether the walk's current path still equals a prefix of `path` (each
  // new component is compared once, so the walk stays linear).
  std::vector<size_t> candidates;  // lengths of path, its parent, ..., ""
  for (std::string p = path;; p = parentPath(p)) {
    candidates.push_back(p.size());
    if (p.empty()) break;
  }
  std::vector<int> found(candidates.size(), 0);
  Walker w(text_, start_);
  w.target = &path;
  w.run([&](size_t, int line) {
    if (!w.matched) return true;
    for (size_t i = 0; i < candidates.size(); ++i)
      if (candidates[i] == w.path().size()) found[i] = line;  // a later duplicate wins, as in nlohmann
    return true;
  });
  for (size_t i = 0; i < candidates.size(); ++i)
    if (found[i]) return found[i];
  return 1;
}

std::string JsonLocator::findNumber(const std::string& token) const {
  std::string result;
  Walker w(text_, start_);
  w.run([&](size_t offset, int) {
    if (text_.compare(offset, token.size(), token) != 0) return true;
    size_t end = offset + token.size();
    bool whole = end >= text_.size() || std::string(",]} \t\r\n").find(text_[end]) != std::string::npos;
    if (!whole) return true;
    result = w.path();
    return false;
  });
  return result;
}

}  // namespace tdpm::scene
