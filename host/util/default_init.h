#pragma once

#include <memory>
#include <new>
#include <type_traits>
#include <utility>

namespace pr {

// An allocator whose construct() without arguments default-initialises: a vector of trivial
// records that is written whole right after resize() skips the zeroing a plain vector does
// first (the motion steps' packets: a few hundred MB a frame on a skinned character).
template <class T, class Base = std::allocator<T>>
class DefaultInitAllocator : public Base {
  using Traits = std::allocator_traits<Base>;

 public:
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U, typename Traits::template rebind_alloc<U>>;
  };
  using Base::Base;
  DefaultInitAllocator() = default;

  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    Traits::construct(static_cast<Base&>(*this), p, std::forward<Args>(args)...);
  }
};

}  // namespace pr
