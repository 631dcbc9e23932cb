// The curved free-expansion scene's stent (configs/curved_free_expansion.yaml, paper §3.2): the
// 11-ring stent warped onto the same centerline file as the balloon. Compared with the paper's
// counts (588 elements), the crimped radius 0.575 mm measured from the shared centerline
// (core/geometry Centerline::closest, to round-off), and the balloon's placement (both
// centred: equal mid arc lengths).
#include <gtest/gtest.h>

#include <algorithm>

#include "angio/beam/scene.hpp"
#include "angio/geometry/centerline.hpp"

using namespace angio::beam;

TEST(CurvedDevice, StentCoaxialWithTheBalloonCenterline) {
  const std::string dir = std::string(ANGIO_SOURCE_DIR) + "/configs/";
  const BeamScene s = load_beam_scene(dir + "curved_free_expansion.yaml");
  EXPECT_EQ(s.model->num_elements(), 588);
  const auto cl = angio::geometry::read_centerline(dir + "centerlines/curved_arc_r15.txt");
  double smin = 1e9, smax = -1e9;
  for (int n = 0; n < s.model->num_nodes(); ++n) {
    const auto p = cl.closest(s.model->reference_position(n));
    EXPECT_NEAR(p.distance, 0.575, 1e-12) << "node " << n;
    smin = std::min(smin, p.s);
    smax = std::max(smax, p.s);
  }
  EXPECT_NEAR(smax - smin, 16.5, 1e-9);                       // not stretched along the axis
  EXPECT_NEAR(0.5 * (smin + smax), 0.5 * cl.length(), 1e-9);  // centred like the balloon
  // radial fixation of the middle ring w.r.t. the curved axis: 4 nodes on the centerline's
  // normal plane at the middle ring's bottom crowns
  ASSERT_EQ(s.stent->fixation_nodes.size(), 4u);
  for (int n : s.stent->fixation_nodes) EXPECT_NEAR(cl.closest(s.model->reference_position(n)).s, smin + 5 * 1.5, 1e-9);
}
