// cli/frame_pattern.cpp — frame-numbered output names and frame ranges.
#include "cli/frame_pattern.h"

#include <climits>
#include <cctype>

#include "core/error.h"

namespace tdpm::cli {

bool hasFramePlaceholder(const std::string& pattern) { return pattern.find('#') != std::string::npos; }

std::string formatFramePath(const std::string& pattern, int frame) {
  // Built as a string: any run length gives its zero-padded number (a
  // 32-byte snprintf buffer cut runs of 32 or more, and every frame went
  // to one file; issue 27 item 8). checkFramePattern bounds the length.
  const std::string digits = std::to_string(frame);
  std::string out;
  for (size_t i = 0; i < pattern.size();) {
    if (pattern[i] != '#') {
      out += pattern[i++];
      continue;
    }
    size_t run = 0;
    while (i + run < pattern.size() && pattern[i + run] == '#') ++run;
    if (run > digits.size()) out.append(run - digits.size(), '0');
    out += digits;
    i += run;
  }
  return out;
}

namespace {

// A non-negative decimal integer of at most 9 digits, the whole of `s`.
bool parseIndex(const std::string& s, int& v) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  v = std::stoi(s);
  return true;
}

}  // namespace

FrameRange parseFrameRange(const std::string& text, int frames, const std::string& flag) {
  FrameRange r;
  size_t dash = text.find('-');
  std::string a = dash == std::string::npos ? text : text.substr(0, dash);
  std::string b = dash == std::string::npos ? text : text.substr(dash + 1);
  if (!parseIndex(a, r.first) || !parseIndex(b, r.last))
    throw Error(flag + ": expected A-B (first and last frame, from 0), for example 0-23, got '" + text + "'");
  if (r.first > r.last) throw Error(flag + ": the first frame " + a + " comes after the last " + b);
  if (r.last >= frames)
    throw Error(flag + ": frame " + std::to_string(r.last) + " is past the animation's last frame " +
                std::to_string(frames - 1) + " (it has " + std::to_string(frames) + " frames, numbered from 0)");
  return r;
}

void checkFramePattern(const std::string& pattern, const FrameRange& range, const std::string& flag) {
  if (pattern.size() < 4 || pattern.compare(pattern.size() - 4, 4, ".exr") != 0)
    throw Error(flag + ": '" + pattern + "' must end in .exr (the PNG preview goes beside it)");
  if (range.count() > 1 && !hasFramePlaceholder(pattern))
    throw Error(flag + ": '" + pattern + "' has no # for the frame number, but " + std::to_string(range.count()) +
                " frames are rendered (" + std::to_string(range.first) + "-" + std::to_string(range.last) +
                "); write for example out/frame_####.exr");
  size_t slash = pattern.find_last_of('/');
  std::string name = slash == std::string::npos ? pattern : pattern.substr(slash + 1);
  if (name == ".exr") throw Error(flag + ": '" + pattern + "' has no file name before .exr");
  // The longest name it gives (the last frame's, or a run's own width) must
  // be a file name: its PNG preview has the same length.
  const std::string longest = formatFramePath(name, range.last);
  if (longest.size() > size_t(NAME_MAX))
    throw Error(flag + ": '" + pattern + "' gives file names of " + std::to_string(longest.size()) +
                " bytes (frame " + std::to_string(range.last) + "), more than a file name may have (" +
                std::to_string(NAME_MAX) + "); use fewer #");
}

}  // namespace tdpm::cli
