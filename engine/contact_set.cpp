#include "engine/contact_set.h"

#include <atomic>
#include <utility>

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

void SleeperCache::touched() {
  static std::atomic<std::uint64_t> stamps{0};
  stamp = ++stamps;
}

void SleeperCache::forget(std::uint32_t entity) {
  if (!asleep(entity)) return;
  touched();
  used -= of[entity].count;
  of[entity] = {};
  partners[entity] = 0;
  --sleepers;
}

void SleeperCache::fall_asleep(std::uint32_t entity, std::uint32_t at) {
  forget(entity);
  touched();
  if (entity >= of.size()) {
    of.resize(entity + std::size_t{1});
    partners.resize(of.size(), 0);
  }
  of[entity] = {at, 0, 0};
  ++sleepers;
}

void SleeperCache::keep(std::uint32_t entity, std::span<const WarmStartEntry> from) {
  if (!asleep(entity)) return;
  touched();
  Sleeper& s = of[entity];
  used -= s.count;
  s.begin = static_cast<std::uint32_t>(entries.size());
  s.count = 0;
  std::uint32_t& bits = partners[entity];
  bits = 0;
  for (const WarmStartEntry& e : from)
    if (live(e, s.since)) {
      entries.push_back(e);
      bits |= partner_bit(e.partner);
      ++s.count;
    }
  used += s.count;
}

void SleeperCache::compact() {
  if (entries.size() <= 2 * used + 4096) return;
  touched();
  std::vector<WarmStartEntry> packed;
  packed.reserve(used);
  for (Sleeper& s : of) {
    if (s.since == kAwake) continue;
    const std::uint32_t begin = static_cast<std::uint32_t>(packed.size());
    packed.insert(packed.end(), entries.begin() + s.begin, entries.begin() + s.begin + s.count);
    s.begin = begin;
  }
  entries = std::move(packed);
}

void SleeperCache::clear() {
  touched();
  of.clear();
  partners.clear();
  entries.clear();
  sleepers = used = 0;
}

void ContactSet::rows_cache(std::span<const std::uint32_t> entity, std::vector<std::uint32_t>& begin,
                            std::vector<WarmStartEntry>& out) const {
  begin.clear();
  out.clear();
  if (warm_begin.empty()) return;
  const std::size_t rows = warm_begin.size() - 1;
  begin.reserve(rows + 1);
  begin.push_back(0);
  for (std::size_t k = 0; k < rows; ++k) {
    const RowEntries e = row_entries(static_cast<std::uint32_t>(k), k < entity.size() ? entity[k] : SleeperCache::kAwake);
    for (const WarmStartEntry& w : e.entries)
      if (!e.kept || e.kept->live(w, e.since)) out.push_back(w);
    begin.push_back(static_cast<std::uint32_t>(out.size()));
  }
}

void ContactSet::set_rows_cache(std::vector<std::uint32_t> begin, std::vector<WarmStartEntry> entries) {
  warm_begin = std::move(begin);
  warm = std::move(entries);
  row_slept.clear();
  kept.clear();
}

void ContactSet::scale_impulses(float factor) {
  auto scale = [factor](std::vector<WarmStartEntry>& entries) {
    for (WarmStartEntry& e : entries) {
      e.normal_impulse *= factor;
      e.friction_impulse *= factor;
    }
  };
  scale(warm);
  scale(kept.entries);
  kept.touched();
}

}  // namespace ballpit
