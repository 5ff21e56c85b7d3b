// core/huge_pages.cpp — mmap + madvise(MADV_HUGEPAGE).
#include "core/huge_pages.h"

#include <sys/mman.h>

#include <cstdint>
#include <utility>

namespace tdpm {

namespace {
constexpr size_t kHugePage = size_t(2) << 20;
}

HugePageBuffer::HugePageBuffer(size_t bytes) {
  if (bytes == 0) return;
  // One spare huge page, so that the data can start on a 2 MB boundary
  // (huge pages only back aligned 2 MB ranges).
  size_t mapped = bytes + kHugePage;
  if (mapped < bytes) return;  // overflow
  void* p = mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) return;
  uintptr_t start = (reinterpret_cast<uintptr_t>(p) + kHugePage - 1) & ~uintptr_t(kHugePage - 1);
#ifdef MADV_HUGEPAGE
  // Only a request: without transparent huge pages it stays on 4 KB pages.
  (void)madvise(reinterpret_cast<void*>(start), bytes, MADV_HUGEPAGE);
#endif
  base_ = p;
  mapped_ = mapped;
  data_ = reinterpret_cast<void*>(start);
  bytes_ = bytes;
}

void HugePageBuffer::release() {
  if (base_) munmap(base_, mapped_);
  base_ = data_ = nullptr;
  mapped_ = bytes_ = 0;
}

HugePageBuffer::~HugePageBuffer() { release(); }

HugePageBuffer& HugePageBuffer::operator=(HugePageBuffer&& o) noexcept {
  if (this != &o) {
    release();
    base_ = std::exchange(o.base_, nullptr);
    mapped_ = std::exchange(o.mapped_, 0);
    data_ = std::exchange(o.data_, nullptr);
    bytes_ = std::exchange(o.bytes_, 0);
  }
  return *this;
}

}  // namespace tdpm
