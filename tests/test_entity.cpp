#include <gtest/gtest.h>

#include "engine/entity.h"
#include "engine/error.h"

using namespace ballpit;

TEST(Entity, DestroyedHandleIsStaleEvenAfterItsSlotIsReused) {
  EntityRegistry r;
  Entity a = r.create();
  r.destroy(a);
  Entity b = r.create();
  EXPECT_EQ(a.index, b.index);  // the slot is reused...
  EXPECT_FALSE(r.alive(a));     // ...but the old handle does not name the newcomer
  EXPECT_TRUE(r.alive(b));
}

TEST(Entity, DestroyingAStaleHandleIsAnErrorNamingIt) {
  EntityRegistry r;
  Entity a = r.create();
  r.destroy(a);
  try {
    r.destroy(a);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("entity 0 (generation 0)"), std::string::npos) << e.what();
  }
}

TEST(Entity, LiveCountFollowsCreateAndDestroy) {
  EntityRegistry r;
  Entity a = r.create(), b = r.create(), c = r.create();
  r.destroy(b);
  EXPECT_EQ(r.live_count(), 2u);
  EXPECT_TRUE(r.alive(a));
  EXPECT_TRUE(r.alive(c));
}
