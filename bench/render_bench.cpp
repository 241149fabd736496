// Frames per second of the offscreen renderer (textured 640x480) on ellipsoids and sim heads,
// and of new views by texture inheritance (ViewSynthesizer) of an uploaded sim head.
// Prints Google Benchmark JSON by default; the "fps" counter is frames per second.
// llvmpipe's rasteriser threads follow LP_NUM_THREADS (default: the number of cores).
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "capture/camera_model.h"
#include "render/gl_util.h"
#include "render/new_view.h"
#include "render/renderer.h"
#include "render/shapes.h"
#include "sim/head.h"

namespace {

using namespace orthoface;

capture::CameraModel view_camera() {
  return capture::view_camera(capture::ideal_rig(640, 480, 1.6), 30, 10);
}

mesh::TriMesh ellipsoid(int triangles) {  // 2 * segments * (rings - 1) triangles
  const int rings = triangles >= 16000 ? 64 : 32;
  return render::uv_ellipsoid({0, 0, 0}, {76, 115, 98}, rings, 2 * rings, 1024);
}

mesh::TriMesh sim_head(int triangles) {
  sim::HeadOptions o;
  o.target_triangles = triangles;
  return sim::make_head(sim::head_params(3), o).mesh;
}

void run(benchmark::State& state, const mesh::TriMesh& mesh, bool cached,
         const render::RenderOptions& options = {}) {
  render::Renderer renderer;
  const capture::CameraModel cam = view_camera();
  renderer.render(mesh, cam, options);  // upload + warm-up
  for (auto _ : state) {
    if (!cached) renderer.clear_cache();
    benchmark::DoNotOptimize(renderer.render(mesh, cam, options).image.data);
  }
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["triangles"] = double(mesh.triangles.size());
  const char* threads = std::getenv("LP_NUM_THREADS");
  state.SetLabel(std::string("LP_NUM_THREADS=") + (threads ? threads : "default"));
}

void BM_TexturedEllipsoid(benchmark::State& state) {
  run(state, ellipsoid(int(state.range(0))), true);
}
void BM_TexturedEllipsoidReupload(benchmark::State& state) {
  run(state, ellipsoid(int(state.range(0))), false);
}
void BM_TexturedSimHead(benchmark::State& state) {
  run(state, sim_head(int(state.range(0))), true);
}
// Image and mask only (RenderOptions::read_depth = false): what a preview or a video frame needs.
void BM_TexturedSimHeadImageOnly(benchmark::State& state) {
  render::RenderOptions o;
  o.read_depth = false;
  run(state, sim_head(int(state.range(0))), true, o);
}

// A 640x480 new view (yaw 30, pitch 10) of a sim head from its front / side photos, with source
// visibility; arg 1 = pick, 2 = weighted, 3 = pick with per-vertex visibility, 4 = pick reading
// back the image and mask only (no depth), 5 = pick with the per-pixel occlusion test on every
// triangle (skip_unoccluded off: the same image), 6 = pick with floating textures (the two
// photos aligned by optical flow first); the mesh and photos are uploaded once.
void BM_NewViewSimHead(benchmark::State& state) {
  const mesh::TriMesh head = sim_head(4000);
  const capture::RigCalibration rig = capture::ideal_rig(640, 480, 1.4);
  render::Renderer renderer;
  const cv::Mat front = renderer.render(head, rig.front).image;
  const cv::Mat side = renderer.render(head, rig.side).image;
  mesh::TriMesh bare = head;
  bare.uvs.clear();
  bare.texture = cv::Mat();
  render::ViewSynthesizer synth(bare, rig, front, side);
  render::SynthesisOptions o;
  o.blend = state.range(0) == 2 ? render::Blend::Weighted : render::Blend::Pick;
  o.float_textures = state.range(0) == 6;
  o.per_pixel_visibility = state.range(0) != 3;
  o.depth = state.range(0) != 4;
  o.skip_unoccluded = state.range(0) != 5;
  const capture::CameraModel cam = capture::view_camera(rig, 30, 10);
  synth.render(cam, o);
  for (auto _ : state) benchmark::DoNotOptimize(synth.render(cam, o).view.image.data);
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["triangles"] = double(head.triangles.size());
}

// A synthesizer of a sim head and two pairs of its photos (the second 10% darker) that live
// updates alternate between, so each set_photos really changes the textures.
struct LivePhotos {
  capture::RigCalibration rig = capture::ideal_rig(640, 480, 1.4);
  std::array<cv::Mat, 2> pair[2];
  std::unique_ptr<render::ViewSynthesizer> synth;
  bool odd = false;

  LivePhotos() {
    const mesh::TriMesh head = sim_head(4000);
    for (int i = 0; i < 2; ++i) {
      const capture::CameraModel& cam = i == 0 ? rig.front : rig.side;
      pair[0][i] = render::render_once(head, cam).image;
      pair[1][i] = pair[0][i] * 0.9;
    }
    mesh::TriMesh bare = head;
    bare.uvs.clear();
    bare.texture = cv::Mat();
    synth = std::make_unique<render::ViewSynthesizer>(bare, rig, pair[0][0], pair[0][1]);
  }
  void next(render::ColourUpdate update) {
    odd = !odd;
    synth->set_photos(pair[odd][0], pair[odd][1], update);
  }
};

render::ColourUpdate colour_update(const benchmark::State& state) {
  return state.range(0) == 1 ? render::ColourUpdate::Recompute : render::ColourUpdate::Keep;
}

// Live re-texturing: new front / side photos every frame, then one view. Arg 0: the colour
// match is kept (the live station), 1: recomputed on every call.
void BM_NewViewWithNewPhotos(benchmark::State& state) {
  LivePhotos live;
  const capture::CameraModel cam = capture::view_camera(live.rig, 30, 0);
  for (auto _ : state) {
    live.next(colour_update(state));
    benchmark::DoNotOptimize(live.synth->render(cam).view.image.data);
  }
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

// set_photos alone (args as BM_NewViewWithNewPhotos); the time per iteration is its cost.
void BM_SetPhotos(benchmark::State& state) {
  LivePhotos live;
  for (auto _ : state) live.next(colour_update(state));
}

// Reference: the plainest llvmpipe draw of the same mesh in the same process (one colour, no
// texture, colour readback only), so fps ratios survive a noisy, shared machine.
const char* kPlainVs = R"(#version 330 core
layout(location = 0) in vec3 pos;
uniform mat4 clip_from_head;
void main() { gl_Position = clip_from_head * vec4(pos, 1.0); })";
const char* kPlainFs = R"(#version 330 core
out vec4 color;
void main() { color = vec4(0.8, 0.7, 0.6, 1.0); })";

void BM_PlainLlvmpipeReference(benchmark::State& state) {
  const mesh::TriMesh mesh = ellipsoid(int(state.range(0)));
  const capture::CameraModel cam = view_camera();
  render::gl::Context context;
  const GLuint prog = render::gl::program(kPlainVs, kPlainFs, "plain");
  std::vector<float> pos;
  for (const auto& v : mesh.vertices)
    pos.insert(pos.end(), {float(v.x()), float(v.y()), float(v.z())});
  GLuint vao = 0, buf[2] = {0, 0};
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(2, buf);
  glBindBuffer(GL_ARRAY_BUFFER, buf[0]);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(pos.size() * 4), pos.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, nullptr);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buf[1]);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.triangles.size() * 12),
               mesh.triangles.data(), GL_STATIC_DRAW);
  render::gl::Framebuffer fb;
  fb.ensure(cam.width, cam.height, {GL_RGBA8});
  glViewport(0, 0, cam.width, cam.height);
  const auto clip = render::gl::clip_from_head(cam, 500, 1500);
  glUseProgram(prog);
  glUniformMatrix4fv(glGetUniformLocation(prog, "clip_from_head"), 1, GL_FALSE, clip.data());
  glEnable(GL_DEPTH_TEST);
  cv::Mat rgba(cam.height, cam.width, CV_8UC4);
  for (auto _ : state) {
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDrawElements(GL_TRIANGLES, GLsizei(mesh.triangles.size() * 3), GL_UNSIGNED_INT, nullptr);
    glReadPixels(0, 0, cam.width, cam.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  }
  int covered = 0;
  for (int i = 0; i < int(rgba.total()); ++i) covered += rgba.data[4 * i] > 100;
  state.counters["covered_px"] = covered;
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  fb.release();
}

BENCHMARK(BM_PlainLlvmpipeReference)->Arg(4000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TexturedEllipsoid)
    ->Arg(4000)
    ->Arg(16000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_TexturedEllipsoidReupload)->Arg(4000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TexturedSimHead)->Arg(4000)->Arg(16000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TexturedSimHeadImageOnly)
    ->Arg(4000)
    ->Arg(16000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_NewViewSimHead)
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->Arg(4)
    ->Arg(5)
    ->Arg(6)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_NewViewWithNewPhotos)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK(BM_SetPhotos)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> args(argv, argv + argc);
  std::string json = "--benchmark_format=json";  // default; a later flag overrides it
  args.insert(args.begin() + 1, json.data());
  int n = int(args.size());
  benchmark::Initialize(&n, args.data());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
