// tests/test_function_lengths.cpp — the developers' guide rule "no function
// in src/render or src/cli longer than ~80 lines without a stated reason"
// (issue 22), checked by scripts/function_lengths.py over those folders;
// and the script itself finds a long function and accepts a stated reason.
#include <doctest/doctest.h>

#include <fstream>
#include <string>

#include "cli_harness.h"

namespace {

std::string script() { return std::string("python3 '") + TDPM_SOURCE_DIR + "/scripts/function_lengths.py'"; }

}  // namespace

TEST_CASE("function lengths: src/render and src/cli hold none above 80 lines without a reason") {
  const std::string src = std::string(TDPM_SOURCE_DIR) + "/src/";
  tdpm::test::CommandResult r = tdpm::test::runShell(script() + " '" + src + "'render/*.h '" + src + "'render/*.cpp '" + src +
                                         "'cli/*.h '" + src + "'cli/*.cpp");
  CAPTURE(r.output);
  CHECK(r.exitCode == 0);
}

TEST_CASE("function lengths: the script finds a long function, and a stated reason passes it") {
  const std::string dir = tdpm::test::makeTempDir();
  auto write = [&](const std::string& name, const std::string& comment) {
    std::ofstream f(dir + "/" + name);
    f << "namespace x {\n" << comment << "template <class T>\nint f(int a) {\n";
    for (int i = 0; i < 85; ++i) f << "  a += " << i << ";\n";
    f << "  return a;\n}\n}  // namespace x\n";
  };
  write("long.cpp", "// adds\n");
  write("reason.cpp", "// Longer than 80 lines on purpose: a test.\n");
  tdpm::test::CommandResult bad = tdpm::test::runShell(script() + " '" + dir + "/long.cpp'");
  CHECK(bad.exitCode != 0);
  CHECK(bad.output.find("long.cpp:4: 88 lines") != std::string::npos);
  CHECK(tdpm::test::runShell(script() + " '" + dir + "/reason.cpp'").exitCode == 0);
  tdpm::test::runShell("rm -rf '" + dir + "'");
}
