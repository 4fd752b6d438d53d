// Lists refilled every step keep their capacity, so a steady pit allocates nothing a step; but
// capacity kept from the busiest step is held for the rest of the run. A 100k pour, settled after
// 600 steps, held 2.6x the contacts it had in its lists and 2.5x the batches it packed (issue 42):
// the pour's peak, each slab's list at its own peak, and the growth by doubling on top.
#pragma once

#include <cstddef>

namespace ballpit {

// A list is given back memory only when it holds over twice what it needs, so a pit whose lists
// vary by a few percent a step never reallocates, and then keeps a quarter more than it needs.
// Lists under 16 KiB are left alone: too small to matter, and a list that comes and goes (a
// slab's few spanning pairs) would allocate every step.
inline constexpr std::size_t kReleaseAboveTimesNeed = 2;
inline constexpr std::size_t kKeepSmallListBytes = 16 * 1024;

// For a list about to be refilled (its contents are dead; it may be emptied): if its capacity is
// over kReleaseAboveTimesNeed x `need` elements, swaps it for an empty list with room for
// need + need / 4. A fresh buffer, not shrink_to_fit: nothing is copied.
template <class V>
void release_excess_capacity(V& list, std::size_t need) {
  const std::size_t capacity = list.capacity();
  if (capacity <= kReleaseAboveTimesNeed * need || capacity * sizeof(typename V::value_type) <= kKeepSmallListBytes)
    return;
  V fresh(list.get_allocator());
  fresh.reserve(need + need / 4);
  list.swap(fresh);
}

}  // namespace ballpit
