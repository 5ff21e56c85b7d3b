// scene/json_locate.cpp — the one-pass JSON position scanner behind every
// located scene-file error (see json_locate.h). Iterative, not recursive, so
// a maliciously deep file cannot overflow the stack.
#include "scene/json_locate.h"

#include <algorithm>

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

JsonLocator::JsonLocator(const std::string& text) : text_(text) {
  // nlohmann skips a UTF-8 byte-order mark; so do we.
  if (text_.compare(0, 3, "\xEF\xBB\xBF") == 0) pos_ = 3;
  scan();
}

int JsonLocator::line(const std::string& path) const {
  for (std::string p = path;; p = parentPath(p)) {
    auto it = entries_.find(p);
    if (it != entries_.end()) return it->second.line;
    if (p.empty()) return 1;
  }
}

std::string JsonLocator::findNumber(const std::string& token) const {
  std::string best;
  size_t bestOffset = std::string::npos;
  for (const auto& [path, e] : entries_) {
    if (e.offset >= bestOffset || text_.compare(e.offset, token.size(), token) != 0) continue;
    size_t end = e.offset + token.size();
    bool whole = end >= text_.size() || std::string(",]} \t\r\n").find(text_[end]) != std::string::npos;
    if (whole) { best = path; bestOffset = e.offset; }
  }
  return best;
}

void JsonLocator::skipWhitespace() {
  while (pos_ < text_.size()) {
    char c = text_[pos_];
    if (c == '\n') ++line_;
    else if (c != ' ' && c != '\t' && c != '\r') return;
    ++pos_;
  }
}

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

// Reads the string at pos_ (which is '"'), decoding escapes exactly as
// nlohmann does, so that keys in paths match the parsed object's keys.
bool JsonLocator::readString(std::string* decoded) {
  ++pos_;
  while (pos_ < text_.size()) {
    char c = text_[pos_++];
    if (c == '"') return true;
    if (c != '\\') { if (decoded) decoded->push_back(c); continue; }
    if (pos_ >= text_.size()) return false;
    char e = text_[pos_++];
    unsigned cp = 0;
    switch (e) {
      case 'b': cp = '\b'; break;
      case 'f': cp = '\f'; break;
      case 'n': cp = '\n'; break;
      case 'r': cp = '\r'; break;
      case 't': cp = '\t'; break;
      case 'u': {
        if (!readHex4(text_, pos_, &cp)) return false;
        pos_ += 4;
        unsigned low = 0;  // a surrogate pair is one code point
        if (cp >= 0xD800 && cp <= 0xDBFF && text_.compare(pos_, 2, "\\u") == 0 &&
            readHex4(text_, pos_ + 2, &low) && low >= 0xDC00 && low <= 0xDFFF) {
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

void JsonLocator::skipScalar() {
  while (pos_ < text_.size() && std::string(",]} \t\r\n").find(text_[pos_]) == std::string::npos) ++pos_;
}

// Records the value starting at pos_ and enters it if it is a container.
bool JsonLocator::beginValue(const std::string& path) {
  skipWhitespace();
  if (pos_ >= text_.size()) return false;
  entries_.emplace(path, Entry{line_, pos_});
  char c = text_[pos_];
  if (c == '{' || c == '[') {
    ++pos_;
    stack_.push_back(Frame{c == '{', path, 0, {}});
    return true;
  }
  if (c == '"') return readString(nullptr);
  skipScalar();
  return true;
}

// Handles the next member/element of the innermost container, or its end.
bool JsonLocator::nextInFrame() {
  skipWhitespace();
  if (pos_ >= text_.size()) return false;
  char c = text_[pos_];
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
  std::string path;
  if (f.isObject) {
    int keyLine = line_;
    std::string key;
    if (pos_ >= text_.size() || text_[pos_] != '"' || !readString(&key)) return false;
    skipWhitespace();
    if (pos_ >= text_.size() || text_[pos_] != ':') return false;
    ++pos_;
    path = childPath(f.path, key);
    if (std::find(f.keys.begin(), f.keys.end(), key) != f.keys.end()) {
      duplicates_.push_back({path, keyLine});
      // The later value wins in nlohmann, and so in the located position.
      entries_.erase(path);
    }
    f.keys.push_back(key);
  } else {
    path = elementPath(f.path, f.count);
  }
  ++f.count;
  return beginValue(path);  // may push: f is not used afterwards
}

void JsonLocator::scan() {
  if (!beginValue("")) return;
  while (!stack_.empty())
    if (!nextInFrame()) return;
}

}  // namespace tdpm::scene
