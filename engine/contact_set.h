// The contacts of one step, as the narrowphase finds them and the solver consumes them.
//
// Ordering is the parallelism: sphere rows are sorted by grid cell with the x cell index
// slowest, so a "slab" (all cells sharing one x index) is a contiguous row range. A contact
// found by sphere a (the generator) whose partner lies in a's slab or the next one is "local"
// to a's slab: solving it writes only those two slabs. Even slabs are therefore independent of
// each other, and so are odd slabs; the solver sweeps even slabs in parallel, then odd ones,
// then the few "serial" contacts that span more than two slabs (fast spheres) in order. The
// result does not depend on how slabs are spread over threads: that is the determinism.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "engine/math.h"

namespace ballpit {

// Partner of a contact that is not another sphere: a pit plane or a joint collider.
inline constexpr std::uint32_t kPlaneTag = 0x80000000u;
inline constexpr std::uint32_t kColliderTag = 0x40000000u;
inline constexpr std::uint32_t kTagMask = kPlaneTag | kColliderTag;

// A contact as the narrowphase finds it. The impulses are those the step starts from (last
// step's, from the warm-start cache). The solver works on copies and leaves its results in the
// cache: it never writes the contact lists, so the once-a-step walks over them read 32 bytes a
// contact.
struct Contact {
  std::uint32_t a;             // sphere row that generated the contact
  std::uint32_t b;             // partner sphere row, or kPlaneTag|plane, or kColliderTag|row
  float normal_impulse;        // accumulated normal impulse of one substep (unit: N s)
  Vec3 friction_impulse;       // accumulated tangential impulse of one substep (unit: N s)
  float friction;              // combined Coulomb coefficient
  float restitution;           // combined restitution

  // Carried a normal impulse at the end of the last step: no impact (systems/contact_kernel.h).
  bool loaded_last_step() const { return normal_impulse > 0.0f; }
};
static_assert(sizeof(Contact) == 32);

// Impulses carried from one step to the next, keyed by the generating sphere's row at the end
// of the step and the partner's entity index (or tagged plane/collider id).
struct WarmStartEntry {
  std::uint32_t partner;
  float normal_impulse;
  Vec3 friction_impulse;
};

// Bit of a partner in a summary of a row's warm-start entries (systems/narrowphase.cpp):
// Fibonacci hashing of the partner to one of 32 bits.
inline std::uint32_t partner_bit(std::uint32_t partner) { return 1u << ((partner * 0x9E3779B1u) >> 27); }

// The warm-start entries sleepers keep, by entity, written once as each falls asleep and not
// touched again while it sleeps: a sleeper's pairs with other sleepers, its floor, walls and
// colliders are neither found nor solved, so their impulses would leave the per-row cache in the
// first step it sleeps, and the region would wake cold. Copied into the per-row cache every step
// instead, they cost most of a settled pit's step (systems/solver.cpp, keep_sleepers). An entry
// stays live while its partner is a plane or a collider, or has slept since the entry's owner
// fell asleep or longer: a partner that woke left it, and the pair's impulse is in the per-row
// cache again from then on.
struct SleeperCache {
  static constexpr std::uint32_t kAwake = ~0u;  // `since` of an entity that was awake
  // By entity index: the store (ContactSet::stores) at which it was first found asleep, and
  // where its entries lie in `entries`. Entities past the end were awake.
  struct Sleeper {
    std::uint32_t since = kAwake;
    std::uint32_t begin = 0, count = 0;
  };
  std::vector<Sleeper> of;
  // By entity index, apart: partner_bit of its entries (a filter: a bit may be stale; 0 awake).
  // The narrowphase reads it for every sleeping row, 4 bytes at random where a record of 16 in
  // one table was a third of its row pass in the 100k walk.
  std::vector<std::uint32_t> partners;
  std::vector<WarmStartEntry> entries;  // the sleepers' spans, and holes left by those that woke
  std::size_t sleepers = 0;             // entities with since != kAwake
  std::size_t used = 0;                 // entries in their spans
  // A stamp that no other content of any cache shares: every change through the methods below
  // takes a new one, and a copy takes it with the entries, so two caches with one stamp hold the
  // same (a snapshot copies the cache only when it changed: capture_snapshot). 0: empty, as made.
  std::uint64_t stamp = 0;
  void touched();

  std::uint32_t since_of(std::uint32_t entity) const { return entity < of.size() ? of[entity].since : kAwake; }
  bool asleep(std::uint32_t entity) const { return since_of(entity) != kAwake; }
  // Is an entry of a sleeper that fell asleep at `owner_since` still live?
  bool live(const WarmStartEntry& e, std::uint32_t owner_since) const {
    return (e.partner & kTagMask) || since_of(e.partner) <= owner_since;
  }
  std::span<const WarmStartEntry> entries_of(std::uint32_t entity) const {
    if (!asleep(entity)) return {};
    const Sleeper& s = of[entity];
    return {entries.data() + s.begin, s.count};
  }
  // The entity woke, or is gone: its entries are dropped.
  void forget(std::uint32_t entity);
  // The entity fell asleep at store `at`, with no entries yet; then the live ones of `from`
  // (once every sphere that fell asleep with it is marked, so that their pairs stay).
  void fall_asleep(std::uint32_t entity, std::uint32_t at);
  void keep(std::uint32_t entity, std::span<const WarmStartEntry> from);
  // Packs the spans in entity order when holes outnumber the entries in use.
  void compact();
  void clear();
};

// Contacts generated by the rows of one slab.
struct SlabContacts {
  std::vector<Contact> pairs;    // partner in this slab or the next: solved in the slab's phase
  std::vector<Contact> statics;  // planes and joint colliders: touch only this slab's rows
  std::vector<Contact> serial;   // partner further away (fast spheres): solved serially
};

struct ContactSet {
  std::vector<SlabContacts> slabs;  // one per grid x index; the lists keep their capacity

  // Warm-start cache: entries of row k (row order at the end of the step that wrote them) are
  // warm[warm_begin[k] .. warm_begin[k + 1]); the rows that slept then have theirs in `kept`
  // instead (row_slept[k] = 1). `stores` counts the solves that wrote it.
  std::vector<std::uint32_t> warm_begin;
  std::vector<WarmStartEntry> warm;
  std::vector<std::uint8_t> row_slept;
  SleeperCache kept;
  std::uint32_t stores = 0;

  // Row k's entries of the last step (k in that step's rows): warm's, or its entity's in `kept`,
  // the live ones among them. A view for lookups: find() and what it may skip.
  struct RowEntries {
    std::span<const WarmStartEntry> entries;
    const SleeperCache* kept = nullptr;  // set: entries are a sleeper's, filtered by live()
    std::uint32_t since = 0;
    const WarmStartEntry* find(std::uint32_t partner) const {
      for (const WarmStartEntry& e : entries)
        if (e.partner == partner && (!kept || kept->live(e, since))) return &e;
      return nullptr;
    }
  };
  RowEntries row_entries(std::uint32_t row, std::uint32_t entity) const {
    return row < row_slept.size() && row_slept[row] ? kept_entries(entity) : fresh_entries(row);
  }
  // The row's entries in warm (a row that did not sleep), and an entity's kept ones.
  RowEntries fresh_entries(std::uint32_t row) const {
    if (row + 1 >= warm_begin.size()) return {};
    return {{warm.data() + warm_begin[row], warm.data() + warm_begin[row + 1]}};
  }
  RowEntries kept_entries(std::uint32_t entity) const {
    if (!kept.asleep(entity)) return {};
    return {kept.entries_of(entity), &kept, kept.since_of(entity)};
  }
  // Every row's live entries as one per-row cache (what a snapshot stores), by the row's entity.
  void rows_cache(std::span<const std::uint32_t> entity, std::vector<std::uint32_t>& begin,
                  std::vector<WarmStartEntry>& out) const;
  // A per-row cache to start from (a snapshot's): every row counts as awake when it was written.
  void set_rows_cache(std::vector<std::uint32_t> begin, std::vector<WarmStartEntry> entries);
  // Multiplies every kept impulse (engine/world.h: set_substeps).
  void scale_impulses(float factor);

  // Rows with a sphere-sphere contact that carried load at the end of the last step
  // (Contact::loaded_last_step()), 1 by row: spheres resting in a pile. The narrowphase marks them
  // as it makes the contacts; the solver treats their impacts differently (systems/solver.cpp).
  std::vector<std::uint8_t> piled;

  // Rows of sleeping spheres the solver struck hard enough to wake (1), by row this step.
  std::vector<std::uint8_t> wake_requests;

  std::size_t pair_count() const;
  std::size_t static_count() const;
  std::size_t serial_count() const;
  std::size_t count() const { return pair_count() + static_count() + serial_count(); }  // all of them
};

}  // namespace ballpit
