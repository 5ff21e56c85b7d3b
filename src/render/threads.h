// render/threads.h — limits the worker threads of every parallel loop
// (TBB) for as long as the object lives. Keeps TBB out of cli/.
#pragma once
#include <memory>

namespace tdpm {

class ThreadLimit {
 public:
  explicit ThreadLimit(int maxThreads);  // <= 0: no limit
  ~ThreadLimit();
  static int hardwareThreads();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tdpm
