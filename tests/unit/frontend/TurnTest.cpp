// The turns that bring a face of a box up for a 3-axis machine (docs/setups.md):
// proper rotations by multiples of 90 deg that take the face's outward
// normal to +z, with the box's lowest corner kept, checked on the box's
// corners directly.
#include "frontend/lowering/Lowerer.h"

#include <catch2/catch.hpp>

using namespace stepnc;
using namespace stepnc::lowering;

TEST_CASE("turns bring each face of a box up and keep its lowest corner", "[lowering][setups]") {
  RawExtent raw;
  raw.min = Vec3(-10, 5, 2);
  raw.max = Vec3(90, 65, 42);  // 100 x 60 x 40
  const std::pair<Vec3, const char *> faces[] = {
      {Vec3(1, 0, 0), "+x"}, {Vec3(-1, 0, 0), "-x"}, {Vec3(0, 1, 0), "+y"}, {Vec3(0, -1, 0), "-y"}, {Vec3(0, 0, -1), "-z"}};
  for (const auto &[normal, face] : faces) {
    CAPTURE(face);
    const std::optional<Turn> t = Lowerer::turnFor(normal, raw);
    REQUIRE(t);
    CHECK(t->face == face);
    CHECK(t->rotation.determinant() == Approx(1));
    CHECK((t->rotation * t->rotation.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-12);
    CHECK((t->direction(normal) - Vec3::UnitZ()).norm() < 1e-12);
    // Every entry a whole number: multiples of 90 deg.
    for (int i = 0; i < 9; ++i)
      CHECK(t->rotation.data()[i] == std::round(t->rotation.data()[i]));
    // The turned corners: lowest where the box's lowest was; the face that
    // is up is the top: the box's extent along the normal is the new height.
    Vec3 lo = Vec3::Constant(1e300), hi = -lo;
    for (int c = 0; c < 8; ++c) {
      const Vec3 p = t->point(Vec3(c & 1 ? raw.max.x() : raw.min.x(), c & 2 ? raw.max.y() : raw.min.y(),
                                   c & 4 ? raw.max.z() : raw.min.z()));
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    CHECK((lo - raw.min).norm() < 1e-9);
    CHECK(hi.z() - lo.z() == Approx(((raw.max - raw.min).cwiseProduct(normal)).cwiseAbs().sum()));
    // A point on the face (its centre) lands on the top.
    const Vec3 centre = (raw.min + raw.max) / 2 + normal.cwiseProduct(raw.max - raw.min) / 2;
    CHECK(t->point(centre).z() == Approx(hi.z()));
  }
}

TEST_CASE("an axis along no face of a box has no turn", "[lowering][setups]") {
  CHECK_FALSE(Lowerer::turnFor(Vec3(1, 0, 1).normalized(), std::nullopt));
  CHECK_FALSE(Lowerer::turnFor(Vec3(0, 0, 1), std::nullopt));  // the top needs none
}
