// tests/test_huge_pages.cpp — core/huge_pages.h: the memory is zeroed,
// writable over its whole size, aligned to 2 MB, and moves without a copy.
#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <utility>

#include "core/huge_pages.h"

using namespace tdpm;

TEST_CASE("huge pages: zeroed, writable, 2 MB aligned memory that moves") {
  const size_t bytes = (size_t(5) << 20) + 123;  // not a whole number of pages
  HugePageBuffer a(bytes);
  REQUIRE(a.data() != nullptr);
  CHECK(a.bytes() == bytes);
  CHECK(reinterpret_cast<uintptr_t>(a.data()) % (uintptr_t(2) << 20) == 0);
  auto* p = static_cast<unsigned char*>(a.data());
  size_t nonZero = 0;
  for (size_t i = 0; i < bytes; i += 4096) nonZero += p[i] != 0;
  nonZero += p[bytes - 1] != 0;
  CHECK(nonZero == 0);
  std::memset(p, 0x5a, bytes);
  CHECK(p[bytes - 1] == 0x5a);
  HugePageBuffer b(std::move(a));
  CHECK(a.data() == nullptr);
  CHECK(a.bytes() == 0);
  CHECK(b.data() == p);
  HugePageBuffer c;
  c = std::move(b);
  CHECK(c.data() == p);
  CHECK(static_cast<unsigned char*>(c.data())[12345] == 0x5a);
  HugePageBuffer none(0);
  CHECK(none.data() == nullptr);
}
