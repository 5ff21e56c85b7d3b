// import/pbrt_tokenizer.h — splits pbrt-v3/v4 scene text into tokens
// (bare words, quoted strings, numbers, brackets), each with its line, so
// every later error can name file:line. Comments (#) are dropped.
#pragma once
#include <string>
#include <vector>

namespace tdpm::pbrt {

struct Token {
  enum class Kind { Word, String, Number, Open, Close };
  Kind kind = Kind::Word;
  std::string text;   // word or string contents (escapes resolved); number as written
  double number = 0;  // Number only
  int line = 0;
};

// Throws tdpm::Error "<file>:<line>: ..." on an unterminated string, a bad
// escape, a malformed or non-finite number, a NUL byte or an unexpected
// character.
std::vector<Token> tokenize(const std::string& text, const std::string& file);

}  // namespace tdpm::pbrt
