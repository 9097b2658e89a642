// Objects in the board frame without GL: poses worked out by hand.
#include "scene/objects.h"

#include <gtest/gtest.h>

#include <vector>

namespace blurcue::scene {
namespace {

// A card's corners from its pose, worked out by hand: an 80 x 60 mm card standing at (100, 50) with its lowest edge
// 10 mm above the table, turned 90 deg (its width along +y, facing +x), and one lying flat, unturned.
TEST(CardCorners, FollowItsPoseByHand) {
  VirtualObject card;
  card.kind = VirtualObject::Kind::kCard;
  card.size_mm = 80, card.card_height_mm = 60;
  card.standing = true, card.rotation_deg = 90;
  card.center_board_mm = {100, 50, 40};
  const std::vector<cv::Point3d> expected = {{100, 10, 70}, {100, 90, 70}, {100, 90, 10}, {100, 10, 10}};
  const auto corners = CardCorners(card);
  ASSERT_EQ(corners.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_LT(cv::norm(corners[i] - expected[i]), 1e-9) << i;
  card.standing = false, card.rotation_deg = 0;
  card.center_board_mm = {0, 0, 0};
  const std::vector<cv::Point3d> lying = {{-40, 30, 0}, {40, 30, 0}, {40, -30, 0}, {-40, -30, 0}};
  const auto flat = CardCorners(card);
  for (size_t i = 0; i < 4; ++i) EXPECT_LT(cv::norm(flat[i] - lying[i]), 1e-9) << i;
}

}  // namespace
}  // namespace blurcue::scene
