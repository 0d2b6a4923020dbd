// AllocationBudget and the replaced global operator new / delete it needs (see the header):
// every unaligned form, all through malloc and free. The aligned forms are left alone
// (uncounted; Assimp's readers do not use them). Outside a budget the cost is one
// thread-local load per allocation.
#include "allocation_budget.h"

#include <malloc.h>

#include <cstdlib>
#include <new>

namespace rvr::scene_load {
namespace {
thread_local AllocationBudget* t_budget = nullptr;
}

AllocationBudget::AllocationBudget(uint64_t bytes)
    : limit_(int64_t(bytes > uint64_t(INT64_MAX) ? uint64_t(INT64_MAX) : bytes)), outer_(t_budget) {
  t_budget = this;
}

AllocationBudget::~AllocationBudget() {
  t_budget = outer_;
}

void AllocationBudget::raise(uint64_t bytes) {
  uint64_t room = uint64_t(INT64_MAX) - uint64_t(limit_);
  limit_ += int64_t(bytes < room ? bytes : room);
}

void AllocationBudget::check(size_t bytes) {
  if (bytes > uint64_t(limit_) || held_ + int64_t(bytes) > limit_) {
    exceeded_ = true;
    throw std::bad_alloc();
  }
}

void AllocationBudget::add(size_t bytes) {
  held_ += int64_t(bytes);
  if (held_ > peak_) peak_ = held_;
}

namespace {
AllocationBudget* active_budget() {
  return t_budget;
}
}  // namespace

}  // namespace rvr::scene_load

void* operator new(std::size_t size) {
  rvr::scene_load::AllocationBudget* budget = rvr::scene_load::active_budget();
  // Refused before malloc is asked: a reader's 24 GB request must not reach the system (or a
  // sanitizer's allocation limit) at all.
  if (budget) budget->check(size);
  void* p = std::malloc(size > 0 ? size : 1);
  if (!p) throw std::bad_alloc();
  if (budget) budget->add(malloc_usable_size(p));
  return p;
}

void operator delete(void* p) noexcept {
  if (!p) return;
  if (rvr::scene_load::AllocationBudget* budget = rvr::scene_load::active_budget()) {
    budget->refund(malloc_usable_size(p));
  }
  std::free(p);
}

// The other unaligned forms, on top of those two. libstdc++ would forward them itself, but a
// sanitizer runtime (ASan) brings its own of every form, which would bypass the budget and
// pair its allocations with our frees.
void* operator new[](std::size_t size) {
  return ::operator new(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return ::operator new(size);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return ::operator new(size, std::nothrow);
}
void operator delete[](void* p) noexcept {
  ::operator delete(p);
}
void operator delete(void* p, std::size_t) noexcept {
  ::operator delete(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  ::operator delete(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  ::operator delete(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  ::operator delete(p);
}
