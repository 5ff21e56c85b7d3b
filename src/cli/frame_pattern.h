// cli/frame_pattern.h — output names and frame ranges for animations:
// "out/frame_####.exr" (each run of # becomes the frame number, zero-padded
// to the run's length) and "--frame-range A-B". Pure functions; errors are
// tdpm::Error naming the flag.
#pragma once
#include <string>

namespace tdpm::cli {

// Whether `pattern` holds a run of '#'.
bool hasFramePlaceholder(const std::string& pattern);

// `pattern` with every run of '#' replaced by `frame`, zero-padded to the
// run's length, of any length (a longer number keeps all its digits).
std::string formatFramePath(const std::string& pattern, int frame);

struct FrameRange {
  int first = 0, last = 0;  // inclusive
  int count() const { return last - first + 1; }
};

// "A-B" or "A" (frames A to B of an animation of `frames`, 0-based);
// `flag` names the option in errors.
FrameRange parseFrameRange(const std::string& text, int frames, const std::string& flag = "--frame-range");

// Throws unless one output per frame is possible: a pattern without # for
// more than one frame is an error; the name must end in .exr; the file
// name it gives for range.last must fit NAME_MAX (255 bytes), or the
// error names the pattern.
void checkFramePattern(const std::string& pattern, const FrameRange& range, const std::string& flag = "--output");

}  // namespace tdpm::cli
