// Mesh-analysis benchmark (prints JSON): seed 000's timing table (neighbour, Euclidean and
// geodesic matrices at 550..1760 vertices, plus 10k and 50k), geodesic accuracy against the
// analytic sphere and CGAL's exact Surface_mesh_shortest_path (reference only), and features on
// sim heads and the two scans.
// Usage: analysis_bench [--quick | --timing [REPS [MAX_VERTICES]] | --accuracy | --features
// N_HEADS]
// (--timing: each matrix REPS times, median and min of wall and CPU time, sizes up to MAX_VERTICES)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/analysis_mesh.h"
#include "analysis/geodesics.h"
#include "analysis/mpeg4_features.h"
#include "mesh/mesh_io.h"
#include "render/shapes.h"
#include "sim/head.h"
#include "sim/scan.h"

#ifdef ORTHOFACE_HAVE_CGAL
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_shortest_path.h>
#endif

using namespace orthoface;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

mesh::TriMesh sim_mesh(int seed, int triangles) {
  sim::HeadOptions o;
  o.target_triangles = triangles;
  return analysis::analysis_mesh(sim::make_head(sim::head_params(seed), o).mesh, "bench").mesh;
}

// Wall and CPU time (all threads) of `reps` runs of f: min and median of each.
template <class F>
void time_into(nlohmann::json& row, const std::string& name, int reps, F f) {
  std::vector<double> wall, cpu;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = Clock::now();
    const std::clock_t c0 = std::clock();
    f();
    wall.push_back(ms_since(t0));
    cpu.push_back(1000.0 * double(std::clock() - c0) / CLOCKS_PER_SEC);
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  row[name + "_ms"] = wall[reps / 2];  // median
  row[name + "_ms_min"] = wall[0];
  row[name + "_cpu_ms"] = cpu[reps / 2];
  row[name + "_cpu_ms_min"] = cpu[0];
}

nlohmann::json timing_row(const mesh::TriMesh& m, int reps) {
  const int n = int(m.vertices.size());
  nlohmann::json row{{"vertices", n}, {"triangles", m.triangles.size()}, {"repetitions", reps}};
  time_into(row, "neighbour", reps, [&] { analysis::vertex_neighbors(m); });
  if (n <= 12000) time_into(row, "euclidean_matrix", reps, [&] { analysis::euclidean_matrix(m); });
  if (n <= 2000) {  // wall time, and CPU time of all threads (the machine may be shared)
    time_into(row, "geodesic_matrix_fmm", reps,
              [&] { analysis::geodesic_matrix(m, analysis::GeodesicMethod::kFastMarching); });
    time_into(row, "geodesic_matrix_edge_graph", reps,
              [&] { analysis::geodesic_matrix(m, analysis::GeodesicMethod::kEdgeGraph); });
  } else {  // n single-source runs, timed on 20 and scaled (memory 4 n^2 bytes)
    analysis::GeodesicSolver solver(m);
    std::vector<float> row_values(n);
    time_into(row, "geodesic_single_source_fmm", reps, [&] {
      for (int s = 0; s < 20; ++s) solver.distances_into(s * (n / 20), row_values.data());
    });
    for (const char* k : {"_ms", "_ms_min", "_cpu_ms", "_cpu_ms_min"})
      row[std::string("geodesic_single_source_fmm") + k] =
          row[std::string("geodesic_single_source_fmm") + k].get<double>() / 20.0;
    row["geodesic_matrix_fmm_cpu_ms_extrapolated"] =
        row["geodesic_single_source_fmm_cpu_ms"].get<double>() * n;
    time_into(row, "geodesic_single_source_dijkstra", reps, [&] {
      for (int s = 0; s < 20; ++s) analysis::edge_graph_distances(m, {s * (n / 20)});
    });
    for (const char* k : {"_ms", "_ms_min", "_cpu_ms", "_cpu_ms_min"})
      row[std::string("geodesic_single_source_dijkstra") + k] =
          row[std::string("geodesic_single_source_dijkstra") + k].get<double>() / 20.0;
    if (n <= 12000)  // the whole edge-graph matrix (10k vertices: 400 MB), once
      time_into(row, "geodesic_matrix_edge_graph", 1,
                [&] { analysis::geodesic_matrix(m, analysis::GeodesicMethod::kEdgeGraph); });
  }
  return row;
}

struct Accuracy {
  double mean_rel = 0, max_rel = 0;
};

Accuracy compare(const std::vector<double>& d, const std::vector<double>& ref) {
  double maxd = 0;
  for (double x : ref) maxd = std::max(maxd, x);
  Accuracy a;
  int count = 0;
  for (size_t i = 0; i < d.size(); ++i) {
    if (!(ref[i] > 0.01 * maxd)) continue;
    const double rel = std::abs(d[i] - ref[i]) / ref[i];
    a.mean_rel += rel, a.max_rel = std::max(a.max_rel, rel), ++count;
  }
  a.mean_rel /= std::max(1, count);
  return a;
}

nlohmann::json sphere_accuracy(int levels) {
  const mesh::TriMesh m = render::icosphere(levels, 100.0);
  auto t0 = Clock::now();
  const auto d = analysis::geodesic_distances(m, {0});
  const double fmm_ms = ms_since(t0);
  std::vector<double> truth(d.size());
  for (size_t i = 0; i < d.size(); ++i)
    truth[i] = 100.0 * std::acos(std::clamp(
                           m.vertices[0].normalized().dot(m.vertices[i].normalized()), -1.0, 1.0));
  const Accuracy a = compare(d, truth);
  const Accuracy e = compare(analysis::edge_graph_distances(m, {0}), truth);
  return {{"vertices", m.vertices.size()},         {"fmm_ms", fmm_ms},
          {"fmm_mean_rel_error", a.mean_rel},      {"fmm_max_rel_error", a.max_rel},
          {"dijkstra_mean_rel_error", e.mean_rel}, {"dijkstra_max_rel_error", e.max_rel}};
}

#ifdef ORTHOFACE_HAVE_CGAL
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SM = CGAL::Surface_mesh<K::Point_3>;
using SP = CGAL::Surface_mesh_shortest_path<CGAL::Surface_mesh_shortest_path_traits<K, SM>>;

// `m` as a CGAL surface mesh; `accepted` = m with only the faces CGAL took (it refuses faces
// that would make the mesh non-manifold).
struct CgalMesh {
  SM sm;
  std::vector<SM::Vertex_index> vh;
  mesh::TriMesh accepted;
  explicit CgalMesh(const mesh::TriMesh& m) {
    for (const auto& v : m.vertices) vh.push_back(sm.add_vertex(K::Point_3(v.x(), v.y(), v.z())));
    accepted.vertices = m.vertices;
    for (const auto& t : m.triangles)
      if (sm.add_face(vh[t[0]], vh[t[1]], vh[t[2]]) != SM::null_face())
        accepted.triangles.push_back(t);
  }
};
#endif

nlohmann::json scan_accuracy(const std::string& name, const std::string& path) {
  nlohmann::json j{{"mesh", name}};
  mesh::TriMesh m;
  try {
    m = analysis::analysis_mesh(mesh::read_mesh(path), name).mesh;
  } catch (const std::exception& e) {
    j["skipped"] = e.what();
    return j;
  }
  int src = 0;  // the most forward vertex (nose tip in the scans' frames)
  for (size_t v = 0; v < m.vertices.size(); ++v)
    if (m.vertices[v].z() > m.vertices[src].z()) src = int(v);
#ifdef ORTHOFACE_HAVE_CGAL
  CgalMesh cm(m);
  auto& [sm, vh, same] = cm;  // same: exactly the faces CGAL accepted (both solve one surface)
  j["faces_rejected_by_cgal"] = m.triangles.size() - same.triangles.size();
  auto t0 = Clock::now();
  SP sp(sm);
  sp.add_source_point(vh[src]);
  sp.build_sequence_tree();
  std::vector<double> exact(m.vertices.size());
  for (size_t v = 0; v < m.vertices.size(); ++v)
    exact[v] = sp.shortest_distance_to_source_points(vh[v]).first;
  const double cgal_ms = ms_since(t0);
  for (double& x : exact)
    if (x < 0) x = std::numeric_limits<double>::infinity();  // unreachable
  std::vector<double> fmm;
  double fmm_ms = std::numeric_limits<double>::infinity();
  for (int r = 0; r < 5; ++r) {  // min of 5 (the machine may be shared); CGAL runs once
    t0 = Clock::now();
    fmm = analysis::geodesic_distances(same, {src});
    fmm_ms = std::min(fmm_ms, ms_since(t0));
  }
  const Accuracy a = compare(fmm, exact);
  const Accuracy e = compare(analysis::edge_graph_distances(same, {src}), exact);
  j.update({{"vertices", m.vertices.size()},
            {"cgal_exact_ms", cgal_ms},
            {"fmm_ms_min_of_5", fmm_ms},
            {"speedup", cgal_ms / fmm_ms},
            {"fmm_mean_rel_error", a.mean_rel},
            {"fmm_max_rel_error", a.max_rel},
            {"dijkstra_mean_rel_error", e.mean_rel},
            {"dijkstra_max_rel_error", e.max_rel}});
#else
  auto t0 = Clock::now();
  analysis::geodesic_distances(m, {src});
  j.update({{"vertices", m.vertices.size()}, {"fmm_ms", ms_since(t0)}, {"cgal", "not built"}});
#endif
  return j;
}

// Fast-marching distances on a sim head (seed 000 sizes) against CGAL's exact distances from
// `sources` vertices: the row from the source, the column towards it (every other vertex's run),
// the mean and minimum of the two (whether symmetrising helps), and geodesic_matrix's entries.
nlohmann::json matrix_accuracy(int target_vertices, int sources) {
  const mesh::TriMesh m = sim_mesh(0, 2 * target_vertices);
  const int n = int(m.vertices.size());
  nlohmann::json j{{"vertices", n}, {"sources", sources}};
#ifdef ORTHOFACE_HAVE_CGAL
  CgalMesh cm(m);
  auto& [sm, vh, accepted] = cm;
  if (accepted.triangles.size() != m.triangles.size()) {
    j["skipped"] = "CGAL rejected a face";
    return j;
  }
  analysis::GeodesicSolver solver(m);  // the unsymmetrised runs, one row per source vertex
  analysis::DistanceMatrix g{n, std::vector<float>(size_t(n) * n)};
  for (int s = 0; s < n; ++s) solver.distances_into(s, g.values.data() + size_t(s) * n);
  const auto product = analysis::geodesic_matrix(m, analysis::GeodesicMethod::kFastMarching);
  const auto e = analysis::geodesic_matrix(m, analysis::GeodesicMethod::kEdgeGraph);
  std::map<std::string, std::vector<double>> d;
  std::vector<double> exact;
  for (int k = 0; k < sources; ++k) {
    const int s = k * (n / sources);
    SP sp(sm);
    sp.add_source_point(vh[s]);
    sp.build_sequence_tree();
    for (int v = 0; v < n; ++v) {
      exact.push_back(sp.shortest_distance_to_source_points(vh[v]).first);
      const double row = g.at(s, v), col = g.at(v, s);
      d["row"].push_back(row), d["column"].push_back(col);
      d["mean_of_row_and_column"].push_back(0.5 * (row + col));
      d["min_of_row_and_column"].push_back(std::min(row, col));
      d["geodesic_matrix_fmm"].push_back(product.at(s, v));
      d["dijkstra_row"].push_back(e.at(s, v));
    }
  }
  for (const auto& [name, values] : d) {
    const Accuracy a = compare(values, exact);
    j[name] = {{"mean_rel_error", a.mean_rel}, {"max_rel_error", a.max_rel}};
  }
#else
  j["cgal"] = "not built";
#endif
  return j;
}

// MPEG-4 point (or key vertex) -> the landmarks it is compared with (the first one present).
const std::map<std::string, std::vector<std::string>> kTruthOf = {
    {"9.3", {"nose_tip"}},
    {"9.15", {"subnasale"}},
    {"8.1", {"lip_upper"}},
    {"8.2", {"lip_lower"}},
    {"2.10", {"chin"}},
    {"2.1", {"chin_bottom"}},
    {"nasion", {"nose_bridge"}},
    {"4.3", {"brow_left_center"}},
    {"4.4", {"brow_right_center"}},
    {"3.5", {"eye_left_center"}},
    {"3.6", {"eye_right_center"}},
    {"10.1", {"ear_left_top"}},
    {"10.2", {"ear_right_top"}},
    {"P1_ear_left", {"ear_left_tragus", "ear_left_helix"}},
    {"P2_ear_right", {"ear_right_tragus", "ear_right_helix"}}};

// Distance (mesh units) of each found point with a known landmark, keyed by point name.
std::map<std::string, double> truth_errors(
    const mesh::TriMesh& mesh, const analysis::FeatureReport& r,
    const std::map<std::string, Eigen::Vector3d>& landmarks) {
  std::vector<std::pair<std::string, Eigen::Vector3d>> found;
  for (const auto& p : r.points) found.push_back({p.name, p.position});
  if (r.ear_left) {
    found.push_back({"P1_ear_left", mesh.vertices[*r.ear_left]});
    found.push_back({"P2_ear_right", mesh.vertices[*r.ear_right]});
  }
  std::map<std::string, double> err;
  for (const auto& [name, pos] : found) {
    const auto t = kTruthOf.find(name);
    if (t == kTruthOf.end()) continue;
    for (const auto& lm : t->second)
      if (landmarks.count(lm)) {
        err[name] = (pos - landmarks.at(lm)).norm();
        break;
      }
  }
  return err;
}

nlohmann::json features_vs_truth(const sim::Head& h, double& seconds) {
  const auto t0 = Clock::now();
  const analysis::FeatureReport r = analysis::mpeg4_features(h.mesh);
  seconds = ms_since(t0) / 1000.0;
  nlohmann::json j{{"mesh", h.name}, {"seconds", seconds}, {"points_found", r.points.size()}};
  j["error"] = truth_errors(h.mesh, r, h.landmarks);
  if (r.ear_left) j["left_ear_on_subject_left"] = h.mesh.vertices[*r.ear_left].x() > 0;
  for (const auto& m : r.missing)
    if (m.rfind("note:", 0) != 0) j["missing"].push_back(m);
  return j;
}

nlohmann::json sim_features(int seeds) {
  std::map<std::string, std::vector<double>> err;
  int ears_found = 0, ears_on_correct_side = 0;
  double secs = 0;
  nlohmann::json rows = nlohmann::json::array();
  for (int s = 0; s < seeds; ++s) {
    sim::HeadOptions o;
    o.target_triangles = sim::HeadOptions::kHighTriangles;
    double t = 0;
    const nlohmann::json row = features_vs_truth(sim::make_head(sim::head_params(s), o), t);
    secs += t;
    ears_found += row.contains("left_ear_on_subject_left");
    ears_on_correct_side += row.value("left_ear_on_subject_left", false);
    for (const auto& [name, e] : row["error"].items()) err[name].push_back(e.get<double>());
    rows.push_back(row);
  }
  nlohmann::json j{{"heads", seeds},
                   {"ears_found", ears_found},
                   {"left_ear_on_subject_left", ears_on_correct_side},
                   {"mean_seconds", secs / seeds},
                   {"per_head", rows}};
  for (auto& [name, v] : err) {
    std::sort(v.begin(), v.end());
    double mean = 0;
    for (double x : v) mean += x / v.size();
    j["error_mm"][name] = {
        {"found", v.size()}, {"mean", mean}, {"median", v[v.size() / 2]}, {"max", v.back()}};
  }
  return j;
}

// Nefertiti (nefertiti-lowres.obj: units mm, +y up, face toward +z, subject's left +x, head
// tilted forward): reference vertices picked on the file, 0-based in file order. nose_tip: the
// front-most (max z) vertex of the nose, 6 mm below the tip seen perpendicular to the face line;
// ear helix: the most lateral (max |x|) vertex 40 mm below to 30 mm above the nose, 20..90 mm
// back in z, i.e. the outer rim of each ear (10..20 mm from an ear's centre).
const std::map<std::string, int> kNefertitiPicks = {
    {"nose_tip", 33416}, {"ear_left_helix", 33556}, {"ear_right_helix", 34097}};

nlohmann::json scan_features(const std::string& data) {
  nlohmann::json out = nlohmann::json::array();
  try {  // landmarks picked on the texture and from the profile (sim/scan.cpp), mesh in mm
    double t = 0;
    out.push_back(features_vs_truth(sim::lee_perry_smith_head(data + "/lee_perry_smith_head"), t));
  } catch (const std::exception& e) {
    out.push_back({{"mesh", "Lee Perry-Smith"}, {"skipped", e.what()}});
  }
  try {
    sim::Head h;
    h.mesh = mesh::read_mesh(data + "/nefertiti_scan/nefertiti-lowres.obj");
    h.name = "Nefertiti scan";
    for (const auto& [name, v] : kNefertitiPicks) h.landmarks[name] = h.mesh.vertices.at(v);
    double t = 0;
    out.push_back(features_vs_truth(h, t));
  } catch (const std::exception& e) {
    out.push_back({{"mesh", "Nefertiti"}, {"skipped", e.what()}});
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && !std::strcmp(argv[1], "--quick");
  const bool features_only = argc > 1 && !std::strcmp(argv[1], "--features");
  const bool timing_only = argc > 1 && !std::strcmp(argv[1], "--timing");
  const bool accuracy_only = argc > 1 && !std::strcmp(argv[1], "--accuracy");
  const int reps = timing_only && argc > 2 ? std::max(1, std::atoi(argv[2])) : 1;
  const int max_vertices = timing_only && argc > 3 ? std::atoi(argv[3]) : 1 << 30;
  const std::string data = ORTHOFACE_DATA_DIR;
  nlohmann::json out;
  if (features_only) {
    out["scan_features"] = scan_features(data);
    out["sim_features"] = sim_features(argc > 2 ? std::atoi(argv[2]) : 20);
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  if (accuracy_only) {
    out["matrix_accuracy"] = matrix_accuracy(1760, 10);
    out["sphere_accuracy"] = {sphere_accuracy(4), sphere_accuracy(5), sphere_accuracy(6)};
    out["scan_accuracy"] = {
        scan_accuracy("lee_perry_smith", data + "/lee_perry_smith_head/LeePerrySmith.obj"),
        scan_accuracy("nefertiti", data + "/nefertiti_scan/nefertiti-lowres.obj")};
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  // Seed 000 Tables 1-3 sizes (target triangles ~ 2 x vertices on a closed head).
  std::vector<int> sizes = {550, 725, 794, 900, 1073, 1760, 10000};
  if (!quick) sizes.push_back(50000);
  for (int v : sizes) {
    if (v > max_vertices) continue;
    try {
      out["timing"].push_back(timing_row(sim_mesh(0, 2 * v), reps));
    } catch (const std::exception& e) {
      out["timing"].push_back({{"target_vertices", v}, {"skipped", e.what()}});
    }
  }
  if (timing_only) {
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  out["matrix_accuracy"] = matrix_accuracy(1760, 10);
  out["sphere_accuracy"] = {sphere_accuracy(4), sphere_accuracy(5), sphere_accuracy(6)};
  out["scan_accuracy"] = {
      scan_accuracy("lee_perry_smith", data + "/lee_perry_smith_head/LeePerrySmith.obj"),
      scan_accuracy("nefertiti", data + "/nefertiti_scan/nefertiti-lowres.obj")};
  out["sim_features"] = sim_features(quick ? 3 : 20);
  out["scan_features"] = scan_features(data);
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}
