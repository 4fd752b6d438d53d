// Batching sphere pairs and plane contacts into lanes: what the solver relies on to solve a batch
// at once and still get Gauss-Seidel's result in list order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "systems/batch_kernels.h"
#include "systems/contact_batches.h"
#include "systems/solver_bodies.h"

using namespace ballpit;

namespace {

constexpr std::uint32_t kRows = 600;

Contact pair(std::uint32_t a, std::uint32_t b) {
  Contact c{};
  c.a = a;
  c.b = b;
  return c;
}

// Lists over disjoint row ranges, as slabs of one parity are: each row meets a few neighbours,
// more often close rows than far ones, like a grid-sorted pile.
std::vector<std::vector<Contact>> random_lists(unsigned seed, int lists, std::uint32_t rows_each) {
  std::mt19937 rng(seed);
  std::vector<std::vector<Contact>> out(lists);
  for (int l = 0; l < lists; ++l) {
    const std::uint32_t first = l * rows_each;
    std::uniform_int_distribution<std::uint32_t> step(1, 40), count(0, 6);
    for (std::uint32_t a = first; a + 1 < first + rows_each; ++a)
      for (std::uint32_t k = count(rng); k > 0; --k) out[l].push_back(pair(a, std::min(a + step(rng), first + rows_each - 1)));
  }
  return out;
}

// Where a lane's contact came from: its list and its index there.
struct Source {
  std::size_t list;
  std::uint32_t index;
  bool operator<(const Source& o) const { return std::tie(list, index) < std::tie(o.list, o.index); }
};

struct Packed {
  BatchList batches;
  std::vector<std::vector<Contact>> lists;
  std::vector<Source> sources;  // by tag

  // Packing copies each contact's impulse into its lane, so an impulse set to a distinct tag
  // before packing tells which contact a lane holds.
  Source source(const ContactBatch& batch, int lane) const {
    return sources.at(static_cast<std::size_t>(batch.normal_impulse[lane]));
  }
};

Packed pack(std::vector<std::vector<Contact>> lists, std::vector<std::uint32_t>& last) {
  Packed p{{}, std::move(lists), {}};
  for (std::size_t l = 0; l < p.lists.size(); ++l)
    for (std::uint32_t i = 0; i < p.lists[l].size(); ++i) {
      p.lists[l][i].normal_impulse = static_cast<float>(p.sources.size());
      p.sources.push_back({l, i});
    }
  std::vector<std::vector<Contact>*> views;
  for (auto& l : p.lists) views.push_back(&l);
  const std::vector<float> radius(kRows + SolverBodies::kPadRows, 0.04f);
  const std::vector<std::uint8_t> in_pile(kRows + SolverBodies::kPadRows, 0);
  const Pit pit;
  const PackInput in{radius, in_pile, pit, kRows, last, kStampStride};
  pack_pairs(views, in, p.batches);
  return p;
}

}  // namespace

TEST(ContactBatches, EveryContactHasOneLaneAndNoBatchHoldsASphereTwice) {
  std::vector<std::uint32_t> last(kRows + SolverBodies::kPadRows, 0);
  const Packed p = pack(random_lists(1, 3, kRows / 3), last);
  std::size_t contacts = 0;
  for (const auto& l : p.lists) contacts += l.size();
  std::set<Source> seen;
  for (std::size_t k = 0; k < p.batches.size(); ++k) {
    const ContactBatch& batch = p.batches[k];
    std::set<std::uint32_t> rows;
    for (int lane = 0; lane < kBatchLanes; ++lane) {
      if (!(batch.used >> lane & 1u)) {
        // Padding: two immobile bodies of its own, past the last sphere.
        EXPECT_EQ(batch.a[lane], SolverBodies::pad_a(kRows, lane));
        EXPECT_EQ(batch.b[lane], SolverBodies::pad_b(kRows, lane));
        continue;
      }
      const Source source = p.source(batch, lane);
      EXPECT_TRUE(seen.insert(source).second) << "contact packed twice";
      const Contact& c = p.lists[source.list][source.index];
      EXPECT_EQ(batch.a[lane], c.a);
      EXPECT_EQ(batch.b[lane], c.b);
      EXPECT_TRUE(rows.insert(c.a).second) << "batch " << k << " holds row " << c.a << " twice";
      EXPECT_TRUE(rows.insert(c.b).second) << "batch " << k << " holds row " << c.b << " twice";
    }
  }
  EXPECT_EQ(seen.size(), contacts);
}

TEST(ContactBatches, EachSphereMeetsItsContactsInListOrder) {
  // What makes a batch solved at once equal to its contacts solved one by one in list order: a
  // later contact of a sphere is never in the same or an earlier batch than an earlier one.
  std::vector<std::uint32_t> last(kRows + SolverBodies::kPadRows, 0);
  const Packed p = pack(random_lists(2, 2, kRows / 2), last);
  std::map<Source, std::size_t> batch_of;
  for (std::size_t k = 0; k < p.batches.size(); ++k)
    for (int lane = 0; lane < kBatchLanes; ++lane)
      if (p.batches[k].used >> lane & 1u) batch_of[p.source(p.batches[k], lane)] = k;
  for (std::size_t l = 0; l < p.lists.size(); ++l) {
    std::map<std::uint32_t, std::size_t> latest;  // row -> batch of its latest contact so far
    for (std::uint32_t i = 0; i < p.lists[l].size(); ++i) {
      const Contact& c = p.lists[l][i];
      const std::size_t k = batch_of.at({l, i});
      for (std::uint32_t row : {c.a, c.b}) {
        if (auto it = latest.find(row); it != latest.end()) {
          EXPECT_GT(k, it->second) << "row " << row;
        }
      }
      latest[c.a] = latest[c.b] = k;
    }
  }
}

TEST(ContactBatches, ListsThatShareNoSphereFillTheLanesTogether) {
  // One list is a chain: a contact often waits for the one before. Four such lists packed in
  // turn offer a batch up to four contacts for every one a single list offers (measured: 16% of
  // the lanes filled by one of these lists, 59% by four; a settled pile's slabs: 59% and 97%).
  std::vector<std::uint32_t> last(kRows + SolverBodies::kPadRows, 0);
  auto lanes_used = [](const Packed& p) {
    std::size_t used = 0;
    for (const ContactBatch& b : p.batches) used += static_cast<std::size_t>(__builtin_popcount(b.used));
    return static_cast<double>(used) / static_cast<double>(p.batches.size() * kBatchLanes);
  };
  const auto lists = random_lists(3, 4, kRows / 4);
  const double one = lanes_used(pack({lists[0]}, last));
  std::fill(last.begin(), last.end(), 0u);
  const double four = lanes_used(pack(lists, last));
  std::printf("[ fill ] one list %.0f%% of the lanes, four lists %.0f%%\n", 100 * one, 100 * four);
  EXPECT_GT(four, 3.0 * one);
}

TEST(ContactBatches, TheImpulsesOfEveryPackedContactAreReadBackOnce) {
  // What the solver keeps for the next step's warm start: each contact's lane, with the impulses
  // the passes left there, and nothing from the empty lanes.
  std::vector<std::uint32_t> last(kRows + SolverBodies::kPadRows, 0);
  Packed p = pack(random_lists(4, 2, kRows / 2), last);
  std::map<Source, Vec3> written;  // the friction impulse a pass left in the contact's lane
  for (ContactBatch& batch : p.batches)
    for (int lane = 0; lane < kBatchLanes; ++lane) {
      const Vec3 friction(static_cast<float>(batch.a[lane]), static_cast<float>(batch.b[lane]), static_cast<float>(lane));
      batch.fx[lane] = friction.x();
      batch.fy[lane] = friction.y();
      batch.fz[lane] = friction.z();
      if (batch.used >> lane & 1u) written[p.source(batch, lane)] = friction;
    }
  std::size_t visits = 0;
  std::set<Source> seen;
  for_each_contact(p.batches, [&](std::uint32_t a, std::uint32_t b, float normal, const Vec3& friction) {
    ++visits;
    const Source source = p.sources.at(static_cast<std::size_t>(normal));
    EXPECT_TRUE(seen.insert(source).second) << "contact read twice";
    const Contact& c = p.lists[source.list][source.index];
    EXPECT_EQ(a, c.a);
    EXPECT_EQ(b, c.b);
    EXPECT_EQ(friction, written.at(source));
  });
  EXPECT_EQ(visits, p.sources.size());
}

TEST(ContactBatches, EmptyLanesWriteNothing) {
  // A batch's empty lanes point at padding bodies that every batch shares. A pass must not write
  // them: threads that wrote them (even the same values) took each other's cache lines, and 2
  // threads ran slower than 1. Here the padding is mobile, overlapping and closing, so a pass
  // that stored its empty lanes would change it, on every instruction set this CPU runs.
  std::vector<std::uint32_t> last(kRows + SolverBodies::kPadRows, 0);
  Packed p = pack({{pair(0, 1)}}, last);
  ASSERT_EQ(p.batches.size(), 1u);
  ASSERT_EQ(p.batches[0].used, 1u);
  for (const BatchKernels* kernels : available_batch_kernels()) {
    SolverBodies bodies;
    bodies.rows = kRows;
    bodies.body.resize(kRows + SolverBodies::kPadRows);
    for (std::size_t k = 0; k < bodies.body.size(); ++k) {
      const float x = 0.05f * static_cast<float>(k % 2);  // pairs 0.03 m deep into each other
      bodies.body[k] = {{1.0f - 2.0f * x, 0.5f, 0.0f, 1.0f}, {0.1f, 0.2f, 0.3f, 0.0f}, {x, 1.0f, 0.0f, 0.04f}, {}};
    }
    const std::vector<SolverBody> padding(bodies.body.begin() + kRows, bodies.body.end());
    const SolverBody first = bodies.body[0];
    BatchPassArgs args;
    args.params = {1.0f / 360.0f, 360.0f, 0.4f * 360.0f, 4.0f, 0.5f};
    for (const bool spin : {false, true})
      for (const ContactPass pass : {ContactPass::WarmStart, ContactPass::Solve, ContactPass::Relax}) {
        BatchPassResult result;
        ContactBatch* batch = p.batches.data();
        kernels->get(BatchKind::Pairs, pass, spin)(batch, batch + 1, bodies, args, result);
      }
    EXPECT_NE(bodies.body[0].velocity.x, first.velocity.x) << kernels->name << ": the used lane must act";
    for (std::size_t k = 0; k < padding.size(); ++k) {
      const SolverBody& now = bodies.body[kRows + k];
      EXPECT_EQ(std::memcmp(&now, &padding[k], sizeof(SolverBody)), 0) << kernels->name << ": padding body " << k;
    }
  }
}
