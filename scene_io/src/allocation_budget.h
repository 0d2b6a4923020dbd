// A cap on the heap memory one thread holds inside a scope. Private to scene_io/src.
//
// Assimp's readers trust the counts in a file's header: a 100-byte OFF, PLY or Collada file
// that declares 300 million vertices makes the reader allocate and zero gigabytes before it
// finds the file empty (found by fuzzing; tests/fuzz/regressions/mesh). Checking each format's
// counts ourselves would be a race with every reader, so the import runs under a budget
// instead: while an AllocationBudget is alive on a thread, `operator new` on that thread counts
// the bytes it hands out (less those freed) and throws std::bad_alloc past the budget, which
// Assimp turns into an import error. Everything else allocates as before.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rvr::scene_load {

class AllocationBudget {
 public:
  explicit AllocationBudget(uint64_t bytes);
  ~AllocationBudget();
  AllocationBudget(const AllocationBudget&) = delete;
  AllocationBudget& operator=(const AllocationBudget&) = delete;

  // Allows `bytes` more (an importer opening another file).
  void raise(uint64_t bytes);
  uint64_t limit() const { return uint64_t(limit_); }
  // Whether an allocation was refused (the importer may report it as something else).
  bool exceeded() const { return exceeded_; }
  // The most bytes held at once inside the scope.
  uint64_t peak() const { return peak_ > 0 ? uint64_t(peak_) : 0; }

  // Called by operator new / delete on this thread while the budget is active, with the
  // sizes malloc really gave (malloc_usable_size), so that counts in and out match.
  void check(size_t bytes);  // throws std::bad_alloc when `bytes` more would pass the budget
  void add(size_t bytes);
  void refund(size_t bytes) { held_ -= int64_t(bytes); }

 private:
  int64_t limit_;
  int64_t held_ = 0;  // may go below zero: memory allocated before the scope freed inside it
  int64_t peak_ = 0;
  bool exceeded_ = false;
  AllocationBudget* outer_;
};

}  // namespace rvr::scene_load
