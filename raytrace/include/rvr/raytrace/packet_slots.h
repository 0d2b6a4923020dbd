// Room for one value per ray of a packet (kPacketRays), left unset. closest_packet and a
// PrimaryHitSource write every ray's hit and traversal work of a block; default-constructed
// arrays would write each of them twice per frame, once for nothing.
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>

#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

template <class T>
class PacketSlots {
  // Objects of an implicit-lifetime type come to life in bytes as they are written (C++20):
  // reading a slot before it is written is the only misuse, as with a plain local.
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                "a slot's value begins to exist when it is written");

 public:
  T* data() { return std::launder(reinterpret_cast<T*>(bytes_)); }
  T& operator[](int k) { return data()[k]; }

 private:
  alignas(T) std::byte bytes_[sizeof(T) * kPacketRays];
};

}  // namespace rvr
