// The allocation budget (allocation_budget.h) inside the model-import plugin: the opening
// program's. Its operator new is the one that counts (it comes first for every library the
// program loads), so the plugin's budgets are the program's objects: constructed, raised and
// destroyed by the program's code through the host table, in the plugin's storage (the class
// is the same, built from the same header). Where the plugin's own operator new and delete are
// the ones found (the Python module, loaded by python3, is not searched before the plugin's
// libraries), they forward to the program's, so that Assimp is counted there too.
#include <stdint.h>

#include <cstdlib>
#include <new>

#include "allocation_budget.h"
#include "model_import_abi.h"

namespace rvr::scene_load {

const ModelImportHost* g_host = nullptr;

AllocationBudget::AllocationBudget(uint64_t bytes) {
  g_host->budget_construct(this, bytes);
}

AllocationBudget::~AllocationBudget() {
  g_host->budget_destroy(this);
}

void AllocationBudget::raise(uint64_t bytes) {
  g_host->budget_raise(this, bytes);
}

}  // namespace rvr::scene_load

using rvr::scene_load::g_host;

// Before connect() (the plugin's and Assimp's static constructors) there is no program to
// forward to: malloc and free, which the program's operator delete pairs with.
__attribute__((visibility("default"))) void* operator new(std::size_t size) {
  if (g_host) return g_host->allocate(size);
  void* p = std::malloc(size > 0 ? size : 1);
  if (!p) throw std::bad_alloc();
  return p;
}

__attribute__((visibility("default"))) void operator delete(void* p) noexcept {
  if (g_host)
    g_host->release(p);
  else
    std::free(p);
}

__attribute__((visibility("default"))) void* operator new[](std::size_t size) {
  return ::operator new(size);
}
__attribute__((visibility("default"))) void* operator new(std::size_t size,
                                                          const std::nothrow_t&) noexcept {
  try {
    return ::operator new(size);
  } catch (...) {
    return nullptr;
  }
}
__attribute__((visibility("default"))) void* operator new[](std::size_t size,
                                                            const std::nothrow_t&) noexcept {
  return ::operator new(size, std::nothrow);
}
__attribute__((visibility("default"))) void operator delete[](void* p) noexcept {
  ::operator delete(p);
}
__attribute__((visibility("default"))) void operator delete(void* p, std::size_t) noexcept {
  ::operator delete(p);
}
__attribute__((visibility("default"))) void operator delete[](void* p, std::size_t) noexcept {
  ::operator delete(p);
}
__attribute__((visibility("default"))) void operator delete(void* p,
                                                            const std::nothrow_t&) noexcept {
  ::operator delete(p);
}
__attribute__((visibility("default"))) void operator delete[](void* p,
                                                              const std::nothrow_t&) noexcept {
  ::operator delete(p);
}
