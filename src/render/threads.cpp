// render/threads.cpp — ThreadLimit over tbb::global_control.
#include "render/threads.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

namespace tdpm {

struct ThreadLimit::Impl {
  std::unique_ptr<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(int maxThreads) : impl_(std::make_unique<Impl>()) {
  if (maxThreads > 0)
    impl_->control =
        std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(maxThreads));
}

ThreadLimit::~ThreadLimit() = default;

int ThreadLimit::hardwareThreads() { return tbb::info::default_concurrency(); }

}  // namespace tdpm
