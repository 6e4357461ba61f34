// The stage on the latched markers (stages.hpp): sent once, at step 0; per body its hull filled
// with counter-clockwise triangles that tile it (areas summing to the hull's, each centroid inside
// the hull) and its closed outline, in the body's frame and colour; the fixed spring anchors in
// world.
#include <algorithm>
#include <cmath>

#include "stages.hpp"

namespace rbsim::check {

namespace {

double cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// The triangles of `fill` tile `hull`: each counter-clockwise with its centroid inside, the
// areas summing to the hull's. False when `fill` is not a triangle list at all.
bool check_fill(const std::string& id, const msgs::MarkerMessage& fill, const std::vector<Vec2>& hull,
                Tally& tally) {
  if (fill.type != msgs::kMarkerTriangleList || fill.points.size() % 3 != 0) {
    tally.fail(id + ": hull marker is not a TRIANGLE_LIST");
    return false;
  }
  double area = 0.0, tiles = 0.0;
  for (std::size_t k = 0; k < hull.size(); ++k) area += 0.5 * cross(hull[k], hull[(k + 1) % hull.size()]);
  for (std::size_t k = 0; k + 2 < fill.points.size(); k += 3) {
    const Vec2 &p0 = fill.points[k], &p1 = fill.points[k + 1], &p2 = fill.points[k + 2];
    const double a = 0.5 * cross(p1 - p0, p2 - p0);
    if (a < 0.0) tally.fail(id + ": triangle " + std::to_string(k / 3) + " is clockwise");
    if (!polygon_contains(hull, (p0 + p1 + p2) / 3.0))
      tally.fail(id + ": triangle " + std::to_string(k / 3) + " lies outside the hull");
    tiles += a;
  }
  tally.add(tiles, std::fabs(area), 1e-9 * std::max(1e-12, std::fabs(area)),
            [&] { return id + " filled area"; });
  return true;
}

// `line` is the closed hull as a line strip as wide as the body's diameter.
void check_outline(const std::string& id, const msgs::MarkerMessage& line, const std::vector<Vec2>& hull,
                   double radius, Tally& tally) {
  std::vector<Vec2> outline = hull;
  if (!hull.empty()) outline.push_back(hull.front());
  if (line.type != msgs::kMarkerLineStrip || line.points.size() != outline.size()) {
    tally.fail(id + ": outline is not the closed hull as a LINE_STRIP");
    return;
  }
  for (std::size_t k = 0; k < outline.size(); ++k) {
    const double tol = 1e-12 * std::max(1.0, outline[k].norm());
    tally.add(line.points[k].x(), outline[k].x(), tol, [&] { return id + " outline x"; });
    tally.add(line.points[k].y(), outline[k].y(), tol, [&] { return id + " outline y"; });
  }
  tally.add(line.scale_x, 2.0 * radius, 0.0, [&] { return id + " outline width"; });
}

void check_body_markers(std::size_t b, const std::vector<msgs::MarkerMessage>& markers, const Model& model,
                        const msgs::SceneMessage& desc, const std::string& frame_prefix, Tally& tally) {
  const std::string id = "body " + std::to_string(b);
  const std::string frame = frame_prefix + "body_" + std::to_string(b);
  const msgs::MarkerMessage& fill = markers[2 * b];
  const msgs::MarkerMessage& line = markers[2 * b + 1];
  const Color c = desc.bodies[b].color;
  for (const msgs::MarkerMessage* mk : {&fill, &line}) {
    if (mk->frame_id != frame || !mk->frame_locked || mk->lifetime.sec != 0 || mk->lifetime.nanosec != 0 ||
        mk->color[0] != static_cast<float>(c.r) || mk->color[1] != static_cast<float>(c.g) ||
        mk->color[2] != static_cast<float>(c.b)) {
      tally.fail(id + ": marker in frame '" + mk->frame_id + "', expected '" + frame +
                 "', frame-locked, lifetime 0, the body's colour");
    }
  }
  if (!check_fill(id, fill, model.body_hull[b], tally)) return;
  check_outline(id, line, model.body_hull[b], desc.bodies[b].radius, tally);
}

void check_anchors(const msgs::MarkerMessage& a, const std::vector<Vec2>& anchors, Tally& tally) {
  if (a.frame_id != "world" || a.points.size() != anchors.size()) {
    tally.fail("spring anchors: " + std::to_string(a.points.size()) + " in '" + a.frame_id + "', expected " +
               std::to_string(anchors.size()) + " in world");
    return;
  }
  for (std::size_t k = 0; k < anchors.size(); ++k) {
    tally.add(a.points[k].x(), anchors[k].x(), 0.0, [&] { return "anchor " + std::to_string(k) + " x"; });
    tally.add(a.points[k].y(), anchors[k].y(), 0.0, [&] { return "anchor " + std::to_string(k) + " y"; });
  }
}

}  // namespace

void verify_markers(const StageContext& c, const TopicMessages<std::vector<msgs::MarkerMessage>>& markers,
                    const msgs::SceneMessage& desc, const std::string& states_topic) {
  // Recordings made before the markers were latched sent per-step outlines that are not frame-locked.
  const bool per_step_outlines =
      !markers.messages.empty() && !markers.messages[0].empty() && !markers.messages[0][0].frame_locked;
  if (per_step_outlines) {
    c.report.info(
        "markers: the per-step outlines of recordings made before the latched markers, not verified");
    return;
  }
  if (markers.messages.empty()) return;
  const std::size_t bodies = c.model.mass.size();
  Tally tally;
  if (markers.messages.size() != 1 || markers.log_time[0] != 0) {
    tally.fail("expected one MarkerArray at log time 0, found " + std::to_string(markers.messages.size()));
  }
  const std::vector<msgs::MarkerMessage>& ms = markers.messages[0];
  std::vector<Vec2> anchors;
  for (const SpringDef& sp : c.model.springs) {
    if (sp.body_i == kFixed) anchors.push_back(sp.anchor_i);
    if (sp.body_j == kFixed) anchors.push_back(sp.anchor_j);
  }
  const std::size_t want = 2 * bodies + (anchors.empty() ? 0 : 1);
  if (ms.size() != want) {
    tally.fail(std::to_string(ms.size()) + " markers, expected " + std::to_string(want));
  } else {
    const std::string frame_prefix = body_frame_prefix(states_topic);
    for (std::size_t b = 0; b < bodies; ++b) check_body_markers(b, ms, c.model, desc, frame_prefix, tally);
    if (!anchors.empty()) check_anchors(ms.back(), anchors, tally);
  }
  c.report.line(tally.ok(),
                "markers: once at step 0, " + std::to_string(bodies) +
                    " hulls tiled by counter-clockwise triangles inside them (areas summing to the "
                    "hull's), closed outlines of width 2 r, body frames and colours, " +
                    std::to_string(anchors.size()) + " fixed anchors: " + tally.summary());
}

}  // namespace rbsim::check
