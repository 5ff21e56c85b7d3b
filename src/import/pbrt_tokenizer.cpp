// import/pbrt_tokenizer.cpp — the pbrt lexical syntax: whitespace separates
// tokens, '#' starts a comment to the end of the line, strings are in double
// quotes (with \" \\ \n \t escapes), '[' and ']' delimit value lists, and
// anything else is a number or a bare word (statement names, true/false).
#include "import/pbrt_tokenizer.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "core/error.h"

namespace tdpm::pbrt {

namespace {

[[noreturn]] void fail(const std::string& file, int line, const std::string& what) {
  throw Error(file + ":" + std::to_string(line) + ": " + what);
}

bool isNumberStart(char c, char next) {
  if (std::isdigit(static_cast<unsigned char>(c))) return true;
  if (c == '.') return std::isdigit(static_cast<unsigned char>(next)) != 0;
  if (c == '-' || c == '+') return std::isdigit(static_cast<unsigned char>(next)) || next == '.';
  return false;
}

bool isDelimiter(char c) {
  return std::isspace(static_cast<unsigned char>(c)) || c == '[' || c == ']' || c == '"' || c == '#';
}

}  // namespace

std::vector<Token> tokenize(const std::string& text, const std::string& file) {
  std::vector<Token> out;
  int line = 1;
  size_t i = 0, n = text.size();
  while (i < n) {
    char c = text[i];
    if (c == '\n') { ++line; ++i; continue; }
    if (std::isspace(static_cast<unsigned char>(c))) { ++i; continue; }
    if (c == '#') {
      while (i < n && text[i] != '\n') ++i;
      continue;
    }
    if (c == '\0') fail(file, line, "NUL byte in the file; is this a pbrt scene (text)?");
    Token t;
    t.line = line;
    if (c == '[' || c == ']') {
      t.kind = c == '[' ? Token::Kind::Open : Token::Kind::Close;
      t.text = std::string(1, c);
      ++i;
    } else if (c == '"') {
      t.kind = Token::Kind::String;
      ++i;
      bool closed = false;
      while (i < n) {
        char d = text[i++];
        if (d == '"') { closed = true; break; }
        if (d == '\n') fail(file, t.line, "unterminated string (a string must end on the line it starts)");
        if (d == '\\') {
          if (i >= n) break;
          char e = text[i++];
          switch (e) {
            case '"': t.text += '"'; break;
            case '\\': t.text += '\\'; break;
            case 'n': t.text += '\n'; break;
            case 't': t.text += '\t'; break;
            default: fail(file, line, std::string("unknown escape \\") + e + " in a string");
          }
          continue;
        }
        t.text += d;
      }
      if (!closed) fail(file, t.line, "unterminated string");
    } else {
      size_t start = i;
      while (i < n && !isDelimiter(text[i])) ++i;
      t.text = text.substr(start, i - start);
      if (isNumberStart(c, start + 1 < n ? text[start + 1] : '\0')) {
        t.kind = Token::Kind::Number;
        errno = 0;
        char* end = nullptr;
        t.number = std::strtod(t.text.c_str(), &end);
        if (end != t.text.c_str() + t.text.size()) fail(file, line, "malformed number '" + t.text + "'");
        if (!std::isfinite(t.number) || std::fabs(t.number) > 3.4e38)
          fail(file, line, "number " + t.text + " is not finite as a 32-bit float");
      } else {
        for (char d : t.text)
          if (!std::isalnum(static_cast<unsigned char>(d)) && d != '_' && d != '.' && d != '-' && d != '+')
            fail(file, line, "unexpected character '" + std::string(1, d) + "' in '" + t.text + "'");
        t.kind = Token::Kind::Word;
      }
    }
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace tdpm::pbrt
