// tests/test_issue27_messages.cpp — messages that named the wrong cause
// (issue 27 items 16 and 17, the non-pbrt-budget part): a stratified pbrt
// sampler whose sample count overflowed int, and the notes and warnings of
// the render command that spoke of settings the run did not use.
#include <doctest/doctest.h>

#include <fcntl.h>
#include <pty.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "cli/progress_bar.h"
#include "cli_harness.h"
#include "error_capture.h"
#include "import/pbrt_import.h"

using namespace tdpm;

namespace {

std::string samplerError(const std::string& sampler) {
  return test::errorMessageOf([&] {
    pbrt::importPbrtText("Camera \"perspective\"\nFilm \"image\" \"integer xresolution\" 8 \"integer yresolution\" 4\n" +
                             sampler + "\nWorldBegin\nShape \"sphere\" \"float radius\" 1\n",
                         "s.pbrt");
  });
}

}  // namespace

TEST_CASE("pbrt Sampler: a sample count beyond tdpm's limit is named as such, not as 0 (65536 x 65536 wrapped)") {
  std::string e = samplerError("Sampler \"stratified\" \"integer xsamples\" 65536 \"integer ysamples\" 65536");
  CHECK(e.find("s.pbrt:3") != std::string::npos);
  CHECK(e.find("xsamples 65536 x ysamples 65536 = 4294967296 samples per pixel is more than tdpm's limit of 1048576") !=
        std::string::npos);
  CHECK(samplerError("Sampler \"halton\" \"integer pixelsamples\" 2000000")
            .find("pixelsamples 2000000 samples per pixel is more than tdpm's limit of 1048576") != std::string::npos);
  CHECK(samplerError("Sampler \"stratified\" \"integer xsamples\" 0 \"integer ysamples\" 4")
            .find("xsamples and ysamples must be at least 1, got 0 and 4") != std::string::npos);
  // The limit itself is accepted (the check can pass): 1024 x 1024 = 2^20.
  CHECK(samplerError("Sampler \"stratified\" \"integer xsamples\" 1024 \"integer ysamples\" 1024") == "(no error)");
}

TEST_CASE("render CLI: accumulation --progressive warns of no frames; -m time is not told about accumulation") {
  const std::string scene = std::string(TDPM_SOURCE_DIR) + "/scenes/cube-caustic.json";  // render.frames 20
  std::string dir = test::makeTempDir();
  const std::string small = " --progressive --passes 2 --spp 1 --resolution 16x12 --photons 1000 --global-photons 500 -t 2 -o '" +
                            dir + "/a.exr'";
  auto acc = test::runTdpm("render '" + scene + "' -m accumulation" + small);
  INFO(acc.output);
  REQUIRE(acc.exitCode == 0);
  // It said "20 frames of 1 samples per pixel each take 20 samples per
  // pixel" while the 2 passes took 1 each, and blamed the frames for the photons.
  CHECK(acc.output.find("tdpm: warning: accumulation:") == std::string::npos);
  CHECK(acc.output.find("passes replace in-between frames: accumulation --progressive") != std::string::npos);
  auto time = test::runTdpm("render '" + scene + "' -m time" + small);
  INFO(time.output);
  REQUIRE(time.exitCode == 0);
  CHECK(time.output.find("accumulation --progressive") == std::string::npos);
  CHECK(time.output.find("render.frames in " + scene +
                         " is not used by --progressive (only the accumulation method renders in-between frames)") !=
        std::string::npos);
  // The fixed-budget accumulation still warns (the check can fire).
  auto fixed = test::runTdpm("render '" + scene + "' -m accumulation --spp 1 --resolution 16x12 --photons 1000 "
                             "--global-photons 500 -t 2 -o '" + dir + "/b.exr'");
  CHECK(fixed.output.find("tdpm: warning: accumulation: 20 frames of 1 samples per pixel") != std::string::npos);
  std::system(("rm -rf '" + dir + "'").c_str());
}

// Under mpirun a rank's stderr is a pipe that mpirun copies to its own
// stderr (a file when redirected, where \r and ESC[K landed), and Open MPI
// makes the rank's stdout a pty whatever mpirun's is: no bar at all there.
TEST_CASE("progress bar: drawn on stderr when it is a terminal; never under mpirun, whatever is a terminal") {
  std::fflush(stdout);
  const int savedOut = ::dup(STDOUT_FILENO), savedErr = ::dup(STDERR_FILENO);
  REQUIRE(savedOut >= 0);
  REQUIRE(savedErr >= 0);
  int master = -1, slave = -1;
  REQUIRE(::openpty(&master, &slave, nullptr, nullptr, nullptr) == 0);
  int devnull = ::open("/dev/null", O_WRONLY);
  REQUIRE(devnull >= 0);
  // stdout a terminal, stderr a file: the case of `mpirun ... 2> log`.
  ::dup2(slave, STDOUT_FILENO);
  ::dup2(devnull, STDERR_FILENO);
  std::FILE* mpiBar = cli::ProgressBar::stream(false, true);
  std::FILE* oneBar = cli::ProgressBar::stream(false, false);
  std::FILE* quietBar = cli::ProgressBar::stream(true, true);
  // stderr a terminal, stdout a file: one process draws on stderr, mpirun's rank does not.
  ::dup2(devnull, STDOUT_FILENO);
  ::dup2(slave, STDERR_FILENO);
  std::FILE* oneOnTty = cli::ProgressBar::stream(false, false);
  std::FILE* mpiNoTty = cli::ProgressBar::stream(false, true);
  ::dup2(savedOut, STDOUT_FILENO);
  ::dup2(savedErr, STDERR_FILENO);
  for (int fd : {savedOut, savedErr, master, slave, devnull}) ::close(fd);
  CHECK(mpiBar == nullptr);
  CHECK(oneBar == nullptr);
  CHECK(quietBar == nullptr);
  CHECK(oneOnTty == stderr);
  CHECK(mpiNoTty == nullptr);
}
