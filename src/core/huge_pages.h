// core/huge_pages.h — zeroed memory for large arrays read at random places,
// on 2 MB pages where the kernel gives them.
//
// Why: the caustic guide's cache and photon records (render/caustic_guide.h,
// ~50 MB for a 1024-spp render's guide) are read at random places by every
// eye path's second diffuse vertex. On 4 KB pages each such read also missed
// the TLB, and a page walk under a virtual machine's nested paging costs
// several memory reads of its own. Debian's default transparent huge pages
// mode is "madvise": only memory that asks gets 2 MB pages.
//
// The memory comes from mmap: zeroed, and taking no physical memory until
// written (a huge page is backed whole at its first write).
#pragma once
#include <cstddef>

namespace tdpm {

class HugePageBuffer {
 public:
  HugePageBuffer() = default;
  // bytes of zeroed memory; empty (data() null) when the system refuses.
  explicit HugePageBuffer(size_t bytes);
  ~HugePageBuffer();
  HugePageBuffer(HugePageBuffer&& o) noexcept : base_(o.base_), mapped_(o.mapped_), data_(o.data_), bytes_(o.bytes_) {
    o.base_ = o.data_ = nullptr, o.mapped_ = o.bytes_ = 0;
  }
  HugePageBuffer& operator=(HugePageBuffer&& o) noexcept;
  HugePageBuffer(const HugePageBuffer&) = delete;
  HugePageBuffer& operator=(const HugePageBuffer&) = delete;

  void* data() const { return data_; }
  size_t bytes() const { return bytes_; }

 private:
  void release();
  void* base_ = nullptr;  // the mapping (data_ rounded up to 2 MB inside it)
  size_t mapped_ = 0;
  void* data_ = nullptr;
  size_t bytes_ = 0;
};

}  // namespace tdpm
