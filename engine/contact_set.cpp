#include "engine/contact_set.h"

namespace ballpit {

std::size_t ContactSet::pair_count() const {
  std::size_t n = 0;
  for (const SlabContacts& s : slabs) n += s.pairs.size();
  return n;
}

std::size_t ContactSet::static_count() const {
  std::size_t n = 0;
  for (const SlabContacts& s : slabs) n += s.statics.size();
  return n;
}

std::size_t ContactSet::serial_count() const {
  std::size_t n = 0;
  for (const SlabContacts& s : slabs) n += s.serial.size();
  return n;
}

}  // namespace ballpit
