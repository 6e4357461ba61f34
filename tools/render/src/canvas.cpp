// Drawing one frame with Cairo.
#include <cairo.h>
#include <png.h>

#include <csetjmp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "rbsim/atomic_file.hpp"
#include "rbsim/render.hpp"

#if defined(__SANITIZE_ADDRESS__)
// Cairo's text goes through fontconfig, which keeps its parsed configuration for the life of the
// process on purpose (no API frees it while Cairo may still use it). LeakSanitizer reads this
// function in any process that draws, so only that library's allocations are excused.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libfontconfig.so\n";
}
#endif

namespace rbsim::render {

namespace {
// Colours travel as float32 in messages; rounding here too makes both stage sources identical.
Color as_float(const Color& c) {
  return {static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b)};
}
}  // namespace

Stage stage_of(const Scene& scene, const World& world) {
  Stage s;
  for (std::int32_t b = 0; b < world.body_count(); ++b) {
    const auto hull = world.hull(BodyId{b});
    s.bodies.push_back({{hull.begin(), hull.end()}, as_float(scene.body_colors[b]), world.radius(BodyId{b})});
  }
  for (std::int32_t k = 0; k < world.spring_count(); ++k) {
    s.springs.push_back(world.spring(SpringId{k}));
    s.spring_colors.push_back(as_float(scene.spring_colors[k]));
  }
  s.viewport = scene.viewport;
  s.background = as_float(scene.background);
  s.dt = world.dt();
  s.duration = scene.duration;
  return s;
}

Stage stage_of(const msgs::SceneMessage& m) {
  Stage s;
  for (const auto& b : m.bodies) s.bodies.push_back({b.hull, b.color, b.radius});
  s.springs = m.springs;
  s.spring_colors = m.spring_colors;
  s.viewport = m.viewport;
  s.background = m.background;
  s.dt = m.dt;
  s.duration = m.duration;
  return s;
}

namespace {
Vec2 to_world(const Pose& p, const Vec2& local) {
  const double c = std::cos(p.theta), s = std::sin(p.theta);
  return {c * local.x() - s * local.y() + p.x, s * local.x() + c * local.y() + p.y};
}
Vec2 spring_end(const Stage& stage, std::span<const Pose> poses, std::int32_t body, const Vec2& anchor) {
  if (body == kFixed || body >= static_cast<std::int32_t>(poses.size())) return anchor;
  (void)stage;
  return to_world(poses[body], anchor);
}
}  // namespace

Camera camera_for(const Stage& stage, std::span<const Pose> poses, int width, int height) {
  Camera cam;
  cam.width = width;
  cam.height = height;
  const double shorter = std::min(width, height);
  if (stage.viewport) {
    cam.cx = stage.viewport->cx;
    cam.cy = stage.viewport->cy;
    cam.scale = shorter / (2.0 * stage.viewport->size);
    return cam;
  }
  double lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
  for (std::size_t b = 0; b < stage.bodies.size() && b < poses.size(); ++b) {
    for (const Vec2& v : stage.bodies[b].hull) {
      const Vec2 w = to_world(poses[b], v);
      const double r = stage.bodies[b].radius;
      lo_x = std::min(lo_x, w.x() - r), hi_x = std::max(hi_x, w.x() + r);
      lo_y = std::min(lo_y, w.y() - r), hi_y = std::max(hi_y, w.y() + r);
    }
  }
  for (const SpringDef& s : stage.springs) {
    for (const Vec2& w :
         {spring_end(stage, poses, s.body_i, s.anchor_i), spring_end(stage, poses, s.body_j, s.anchor_j)}) {
      lo_x = std::min(lo_x, w.x()), hi_x = std::max(hi_x, w.x());
      lo_y = std::min(lo_y, w.y()), hi_y = std::max(hi_y, w.y());
    }
  }
  if (!(lo_x <= hi_x && lo_y <= hi_y)) lo_x = lo_y = -1.0, hi_x = hi_y = 1.0;
  const double span_x = std::max(hi_x - lo_x, 1e-6), span_y = std::max(hi_y - lo_y, 1e-6);
  cam.cx = 0.5 * (lo_x + hi_x);
  cam.cy = 0.5 * (lo_y + hi_y);
  cam.scale = 0.8 * std::min(width / span_x, height / span_y);  // 10% margin on each side
  return cam;
}

std::int64_t frame_count(double duration, double fps) {
  if (!std::isfinite(duration * fps)) return INT64_MAX;  // open-ended (rbsim run --frames)
  const double n = std::floor(duration * fps + 1e-9);
  return n < 1.0 ? 1 : static_cast<std::int64_t>(n);
}

double run_duration(std::int64_t steps, double dt, double scene_duration, std::int64_t scene_steps) {
  if (steps == scene_steps && std::isfinite(scene_duration)) return scene_duration;
  return static_cast<double>(steps) * dt;
}

std::int64_t frame_step(std::int64_t frame, double fps, double dt) {
  return static_cast<std::int64_t>(std::ceil(static_cast<double>(frame) / fps / dt - 1e-9));
}

struct Canvas::Impl {
  cairo_surface_t* surface = nullptr;
  cairo_t* cr = nullptr;
};

Canvas::Canvas(int width, int height) : impl_(std::make_unique<Impl>()), width_(width), height_(height) {
  impl_->surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
  impl_->cr = cairo_create(impl_->surface);
  cairo_set_antialias(impl_->cr, CAIRO_ANTIALIAS_GOOD);
}

Canvas::~Canvas() {
  cairo_destroy(impl_->cr);
  cairo_surface_destroy(impl_->surface);
}

void Canvas::draw(const Stage& stage, std::span<const Pose> poses, double time, const Camera& cam) {
  cairo_t* cr = impl_->cr;
  const auto px = [&](const Vec2& w) {
    return Vec2((w.x() - cam.cx) * cam.scale + 0.5 * cam.width,
                0.5 * cam.height - (w.y() - cam.cy) * cam.scale);
  };
  cairo_identity_matrix(cr);
  cairo_set_source_rgb(cr, stage.background.r, stage.background.g, stage.background.b);
  cairo_paint(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);

  // Bodies: the filled hull, outlined with a stroke of width 2 r, i.e. the hull grown by r.
  for (std::size_t b = 0; b < stage.bodies.size() && b < poses.size(); ++b) {
    const Stage::Body& body = stage.bodies[b];
    cairo_new_path(cr);
    for (const Vec2& v : body.hull) {
      const Vec2 p = px(to_world(poses[b], v));
      cairo_line_to(cr, p.x(), p.y());
    }
    cairo_close_path(cr);
    cairo_set_source_rgb(cr, body.color.r, body.color.g, body.color.b);
    cairo_fill_preserve(cr);
    cairo_set_line_width(cr, std::max(2.0 * body.radius * cam.scale, 1.0));
    cairo_stroke(cr);
  }

  // Springs on top, fixed ends marked with a ring.
  const double line = std::max(1.5, 0.0025 * std::min(cam.width, cam.height));
  for (std::size_t k = 0; k < stage.springs.size(); ++k) {
    const SpringDef& s = stage.springs[k];
    const Vec2 a = px(spring_end(stage, poses, s.body_i, s.anchor_i));
    const Vec2 b = px(spring_end(stage, poses, s.body_j, s.anchor_j));
    const Color& c = stage.spring_colors[k];
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    cairo_set_line_width(cr, line);
    cairo_move_to(cr, a.x(), a.y());
    cairo_line_to(cr, b.x(), b.y());
    cairo_stroke(cr);
    for (const auto& [body, end] : {std::pair{s.body_i, a}, std::pair{s.body_j, b}}) {
      if (body != kFixed) continue;
      cairo_new_path(cr);
      cairo_arc(cr, end.x(), end.y(), 2.5 * line, 0.0, 2.0 * M_PI);
      cairo_set_source_rgb(cr, c.r, c.g, c.b);
      cairo_fill_preserve(cr);
      cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
      cairo_set_line_width(cr, 0.6 * line);
      cairo_stroke(cr);
    }
  }

  // Simulated time, top left, in a colour that reads on the background.
  const Color& bg = stage.background;
  const double luminance = 0.2126 * bg.r + 0.7152 * bg.g + 0.0722 * bg.b;
  const double ink = luminance > 0.5 ? 0.1 : 0.92;
  char text[64];
  std::snprintf(text, sizeof text, "t = %.3f s", time);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  const double font = std::max(10.0, 0.028 * cam.height);
  cairo_set_font_size(cr, font);
  cairo_set_source_rgb(cr, ink, ink, ink);
  cairo_move_to(cr, 0.6 * font, 1.4 * font);
  cairo_show_text(cr, text);
}

namespace {
// libpng reports errors by longjmp, so nothing with a destructor lives in this frame.
bool encode_png(png_structp png, png_infop info, std::FILE* f, const unsigned char* data, int stride,
                int width, int height, unsigned char* row) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    const unsigned char* src = data + static_cast<std::ptrdiff_t>(y) * stride;
    for (int x = 0; x < width; ++x) {
      std::uint32_t v;
      std::memcpy(&v, src + 4 * x, 4);  // xRGB in native endianness
      row[3 * x] = static_cast<unsigned char>(v >> 16);
      row[3 * x + 1] = static_cast<unsigned char>(v >> 8);
      row[3 * x + 2] = static_cast<unsigned char>(v);
    }
    png_write_row(png, row);
  }
  png_write_end(png, nullptr);
  return true;
}
}  // namespace

// PNG through libpng at zlib level 1 with the Sub filter: frames of flat colour compress well
// that way at several times the speed of Cairo's own writer (zlib default level).
Status Canvas::write_png(const std::string& path) const {
  cairo_surface_flush(impl_->surface);
  const unsigned char* data = cairo_image_surface_get_data(impl_->surface);
  const int stride = cairo_image_surface_get_stride(impl_->surface);
  AtomicFile file;
  if (Status st = file.open(path); !st) return st;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  std::vector<unsigned char> row(static_cast<std::size_t>(width_) * 3);
  const bool ok =
      info != nullptr && encode_png(png, info, file.stream(), data, stride, width_, height_, row.data());
  png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);
  if (!ok) return Error{path + ": cannot write PNG"};  // file's destructor removes the temporary
  // One frame of hundreds, made again by rerunning the render: renamed into place, not fsynced.
  if (Status st = file.commit(AtomicFile::Durability::RenameOnly); !st) return st;
  return Ok{};
}

std::array<int, 3> Canvas::pixel(int x, int y) const {
  cairo_surface_flush(impl_->surface);
  const unsigned char* data = cairo_image_surface_get_data(impl_->surface);
  const int stride = cairo_image_surface_get_stride(impl_->surface);
  std::uint32_t v = 0;
  std::memcpy(&v, data + static_cast<std::ptrdiff_t>(y) * stride + 4 * x, 4);  // xRGB, native endian
  return {static_cast<int>((v >> 16) & 0xFF), static_cast<int>((v >> 8) & 0xFF), static_cast<int>(v & 0xFF)};
}

}  // namespace rbsim::render
