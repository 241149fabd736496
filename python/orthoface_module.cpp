// The Python module `orthoface`: reconstruction, new views and the mesh analyses on numpy arrays,
// through the same library calls as the command line (docs/python.md). Images are numpy uint8
// H x W x 3 arrays in BGR order, as OpenCV's Python uses. Errors: std::invalid_argument becomes
// ValueError, any other std::exception RuntimeError, with the message the command line prints.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <opencv2/imgcodecs.hpp>

#include "analysis/mpeg4_features.h"
#include "analysis/similarity.h"
#include "capture/camera_model.h"
#include "io/atomic_file.h"
#include "io/image_file.h"
#include "mesh/mesh_io.h"
#include "reconstruct/reconstruction.h"
#include "reconstruct/views.h"
#include "render/new_view.h"
#include "render/renderer.h"

namespace py = pybind11;
namespace fs = std::filesystem;

namespace orthoface::python {
namespace {

// A reconstruction held by Python. `folder_report` is the report.json text of a folder it was
// loaded from (read_reconstruction does not read reports), kept so save() writes it back.
struct Model {
  std::shared_ptr<const reconstruct::Reconstruction> reconstruction;
  std::optional<std::string> folder_report;
};

struct Mesh {
  mesh::TriMesh mesh;
};

bool is_path(const py::handle& obj) {
  return py::isinstance<py::str>(obj) || py::hasattr(obj, "__fspath__");
}

// str or os.PathLike -> path text; anything else is a TypeError naming the argument.
std::string path_of(const py::handle& obj, const std::string& name) {
  if (!is_path(obj))
    throw py::type_error(name + ": expected a str or os.PathLike path, got " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))));
  return py::str(py::module_::import("os").attr("fspath")(obj));
}

// The command line's require_file: the path names an existing regular file.
void require_file(const std::string& path, const std::string& name) {
  if (path.empty()) throw std::runtime_error(name + ": no path given");
  if (!fs::exists(path)) throw std::runtime_error(name + " " + path + ": no such file");
  if (!fs::is_regular_file(path))
    throw std::runtime_error(name + " " + path + ": not a regular file");
}

cv::Mat read_colour_image(const std::string& path, const std::string& name) {
  require_file(path, name);
  cv::Mat image = io::imread_accepted(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(name + " " + path + ": not a readable image");
  return image;
}

// A numpy uint8 H x W x 3 BGR array (copied) or a path to an image file.
cv::Mat image_from(const py::handle& obj, const std::string& name) {
  if (is_path(obj)) return read_colour_image(path_of(obj, name), name);
  if (!py::isinstance<py::array>(obj))
    throw py::type_error(name + ": expected a numpy uint8 H x W x 3 BGR array or a path, got " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))));
  const auto array = py::reinterpret_borrow<py::array>(obj);
  if (!array.dtype().is(py::dtype::of<std::uint8_t>()))
    throw std::invalid_argument(name + ": expected a uint8 image, got dtype " +
                                std::string(py::str(array.dtype())));
  if (array.ndim() != 3 || array.shape(2) != 3)
    throw std::invalid_argument(name + ": expected an H x W x 3 BGR image, got a " +
                                std::to_string(array.ndim()) + "-D array of shape " +
                                std::string(py::str(obj.attr("shape"))));
  if (array.shape(0) < 1 || array.shape(1) < 1)
    throw std::invalid_argument(name + ": the image is empty");
  const auto dense = py::array_t<std::uint8_t, py::array::c_style>::ensure(array);
  cv::Mat image(int(array.shape(0)), int(array.shape(1)), CV_8UC3);
  std::memcpy(image.data, dense.data(), image.total() * 3);
  return image;
}

// Read-only numpy copies of library data.
template <typename T>
py::array_t<T> read_only(py::array_t<T> array) {
  array.attr("setflags")(py::arg("write") = false);
  return array;
}

py::array_t<double> points_array(const std::vector<Eigen::Vector3d>& points) {
  py::array_t<double> a({py::ssize_t(points.size()), py::ssize_t(3)});
  auto m = a.mutable_unchecked<2>();
  for (size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k) m(i, k) = points[i][k];
  return read_only(std::move(a));
}

py::array_t<std::int32_t> triangles_array(const std::vector<std::array<int, 3>>& triangles) {
  py::array_t<std::int32_t> a({py::ssize_t(triangles.size()), py::ssize_t(3)});
  auto m = a.mutable_unchecked<2>();
  for (size_t i = 0; i < triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) m(i, k) = triangles[i][k];
  return read_only(std::move(a));
}

// An 8-bit image (1, 3 or 4 channels) as H x W (x C) uint8.
py::array_t<std::uint8_t> image_array(const cv::Mat& image) {
  cv::Mat dense = image.isContinuous() ? image : image.clone();
  std::vector<py::ssize_t> shape{dense.rows, dense.cols};
  if (dense.channels() > 1) shape.push_back(dense.channels());
  py::array_t<std::uint8_t> a(shape);
  std::memcpy(a.mutable_data(), dense.data, dense.total() * dense.elemSize());
  return read_only(std::move(a));
}

py::tuple xyz(const Eigen::Vector3d& p) { return py::make_tuple(p.x(), p.y(), p.z()); }

const reconstruct::Reconstruction& reconstruction_of(const Model& model) {
  if (!model.reconstruction)
    throw std::invalid_argument("model: empty (not made by reconstruct or load)");
  return *model.reconstruction;
}

Model reconstruct_model(const py::object& front, const py::object& side, const py::object& rig,
                        const std::string& side_camera, bool force, bool check_identity) {
  reconstruct::ReconstructOptions options;  // `orthoface reconstruct`'s defaults
  if (!rig.is_none()) {
    const std::string path = path_of(rig, "rig");
    require_file(path, "rig");
    options.rig = capture::read_rig(path);
  }
  try {
    options.observe.side_camera = vision::parse_side_camera(side_camera);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("side_camera: ") + e.what());
  }
  options.force = force;
  options.check_identity = check_identity;
  options.check();
  const cv::Mat f = image_from(front, "front"), s = image_from(side, "side");
  Model model;
  model.reconstruction =
      std::make_shared<reconstruct::Reconstruction>(reconstruct::from_photos(f, s, options));
  return model;
}

Model load_model(const py::object& dir) {
  const std::string path = path_of(dir, "dir");
  Model model;
  model.reconstruction =
      std::make_shared<reconstruct::Reconstruction>(reconstruct::read_reconstruction(path));
  std::ifstream report(fs::path(path) / "report.json");
  if (report) model.folder_report = std::string(std::istreambuf_iterator<char>(report), {});
  return model;
}

void save_model(const Model& model, const py::object& dir) {
  const std::string path = path_of(dir, "dir");
  reconstruct::write_reconstruction(reconstruction_of(model), path);
  if (model.folder_report)
    io::write_text_atomically((fs::path(path) / "report.json").string(), *model.folder_report);
}

py::object report_dict(const Model& model) {
  const std::string text = model.folder_report ? *model.folder_report
                                               : reconstruct::report_json(reconstruction_of(model));
  return py::module_::import("json").attr("loads")(text);
}

py::array_t<std::uint8_t> render_view(const Model& model, double yaw, double pitch,
                                      const std::string& background, const std::string& head,
                                      const std::optional<std::pair<int, int>>& size,
                                      const std::string& blend,
                                      const std::optional<std::string>& unseen, bool equalize,
                                      bool float_textures) {
  const reconstruct::Reconstruction& r = reconstruction_of(model);
  reconstruct::ViewOptions o;
  try {
    o.synthesis.blend = render::parse_blend(blend);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("blend: ") + e.what());
  }
  try {
    o.background = reconstruct::parse_view_background(background);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("background: ") + e.what());
  }
  if (head != "whole" && head != "face")
    throw std::invalid_argument("head: expected whole or face, not '" + head + "'");
  o.head = head == "face" ? reconstruct::HeadExtent::Face : reconstruct::HeadExtent::Whole;
  if (size) {
    const auto [w, h] = *size;
    if (w < 1 || h < 1 || w > render::kMaxRenderSize || h > render::kMaxRenderSize)
      throw std::invalid_argument("size: " + std::to_string(w) + "x" + std::to_string(h) +
                                  ": each side must be 1.." +
                                  std::to_string(render::kMaxRenderSize));
    o.width = w;
    o.height = h;
  }
  try {
    o.synthesis.unseen = render::parse_unseen_side(unseen.value_or("view"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("unseen: ") + e.what());
  }
  o.unseen_fallback = !unseen;  // as `render` without --unseen
  o.synthesis.equalize = equalize;
  o.synthesis.float_textures = float_textures;
  return image_array(reconstruct::view_image(r, o, yaw, pitch));
}

Mesh mesh_from(const py::object& obj, const std::string& name) {
  if (py::isinstance<Mesh>(obj)) return obj.cast<Mesh>();
  if (!is_path(obj))
    throw py::type_error(name + ": expected an orthoface.Mesh or a mesh path, got " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))));
  const std::string path = path_of(obj, name);
  require_file(path, name);
  return {mesh::read_mesh(path)};
}

py::object features_dict(const Mesh& m, double neighbourhood) {
  if (!(neighbourhood >= 0.001 && neighbourhood <= 0.45))
    throw std::invalid_argument("neighbourhood: " + std::to_string(neighbourhood) +
                                " is outside [0.001, 0.45]");
  analysis::FeatureOptions options;
  options.neighbourhood = neighbourhood;
  options.check();
  const analysis::FeatureReport r = analysis::mpeg4_features(m.mesh, options);
  return py::module_::import("json").attr("loads")(analysis::feature_report_json(m.mesh, r));
}

py::dict similarity_dict(const py::object& a, const py::object& b, int geodesics, double radius) {
  if (geodesics < 3 || geodesics > 360)
    throw std::invalid_argument("geodesics: " + std::to_string(geodesics) + " is outside [3, 360]");
  if (!(radius >= 1e-9 && radius <= 1e9))
    throw std::invalid_argument("radius: " + std::to_string(radius) + " is outside [1e-09, 1e+09]");
  analysis::SimilarityOptions options;
  options.radial_geodesics = geodesics;
  options.radius = radius;
  options.check();
  const Mesh ma = mesh_from(a, "a"), mb = mesh_from(b, "b");
  const analysis::FaceSignature sa = analysis::face_signature(ma.mesh, options);
  const analysis::FaceSignature sb = analysis::face_signature(mb.mesh, options);
  const analysis::SimilarityScores s = analysis::similarity(sa, sb);
  py::dict out;
  out["mean"] = s.mean;
  out["gaussian"] = s.gaussian;
  out["shape_index"] = s.shape_index;
  out["curvedness"] = s.curvedness;
  py::list warnings;
  for (const auto& w : sa.warnings) warnings.append("a: " + w);
  for (const auto& w : sb.warnings) warnings.append("b: " + w);
  out["warnings"] = warnings;
  return out;
}

}  // namespace
}  // namespace orthoface::python

PYBIND11_MODULE(orthoface, m) {
  using namespace orthoface::python;
  namespace rec = orthoface::reconstruct;
  m.doc() =
      "orthoface: a textured 3D face from a front and a side photo, new views of it, and mesh "
      "analyses (MPEG-4 feature points, face similarity). Images are numpy uint8 arrays in BGR "
      "order (H x W x 3), as OpenCV's Python uses. Bad arguments raise ValueError (TypeError for "
      "an argument of the wrong kind), other failures RuntimeError, with the message the "
      "`orthoface` command line prints after 'error: '.";

  py::class_<Model>(m, "Model",
                    "A reconstructed head (orthoface.reconstruct or orthoface.load): the adapted "
                    "mesh in the head frame (mm: origin between the ears, +x toward the side "
                    "camera, +y up, +z out of the face), the photos and the report.")
      .def_property_readonly(
          "vertices",
          [](const Model& self) { return points_array(reconstruction_of(self).mesh.vertices); },
          "N x 3 float64 array (read-only): vertex positions in mm, head frame.")
      .def_property_readonly(
          "triangles",
          [](const Model& self) { return triangles_array(reconstruction_of(self).mesh.triangles); },
          "M x 3 int32 array (read-only): vertex indices of each triangle, counter-clockwise "
          "seen from outside.")
      .def_property_readonly(
          "texture",
          [](const Model& self) -> py::object {
            const cv::Mat& t = reconstruction_of(self).mesh.texture;
            if (t.empty()) return py::none();
            return image_array(t);
          },
          "The mesh's texture image as an H x W x 3 uint8 BGR array (read-only): the front photo "
          "its texture coordinates project into; None for a model loaded from a folder (the "
          "folder's head.png holds the atlas of both photos).")
      .def_property_readonly(
          "landmarks",
          [](const Model& self) {
            py::dict d;
            for (const auto& [name, p] : reconstruction_of(self).landmarks)
              d[name.c_str()] = xyz(p);
            return d;
          },
          "dict: landmark name -> (x, y, z) in mm, head frame (as landmarks.json).")
      .def_property_readonly("report", &report_dict,
                             "dict: the content of report.json (scale, landmarker, confidences, "
                             "warnings, input check, stage timings, mesh size). A loaded model "
                             "gives its folder's report.json.")
      .def("save", &save_model, py::arg("dir"),
           "Writes the reconstruction folder that `orthoface reconstruct --out DIR` writes "
           "(head.obj/.mtl/.png, front.png, side.png, rig.yaml, landmarks.json, "
           "observation.json, report.json). dir: str or os.PathLike; created if missing.")
      .def("__repr__", [](const Model& self) {
        const auto& r = reconstruction_of(self);
        return "<orthoface.Model " + std::to_string(r.mesh.vertices.size()) + " vertices, " +
               std::to_string(r.mesh.triangles.size()) + " triangles, " +
               std::to_string(r.landmarks.size()) + " landmarks>";
      });

  py::class_<Mesh>(m, "Mesh", "A triangle mesh read by orthoface.load_mesh (OBJ, PLY, glTF).")
      .def_property_readonly(
          "vertices", [](const Mesh& self) { return points_array(self.mesh.vertices); },
          "N x 3 float64 array (read-only): vertex positions in the file's units.")
      .def_property_readonly(
          "triangles", [](const Mesh& self) { return triangles_array(self.mesh.triangles); },
          "M x 3 int32 array (read-only): vertex indices of each triangle.")
      .def("__repr__", [](const Mesh& self) {
        return "<orthoface.Mesh " + std::to_string(self.mesh.vertices.size()) + " vertices, " +
               std::to_string(self.mesh.triangles.size()) + " triangles>";
      });

  m.def("reconstruct", &reconstruct_model, py::arg("front"), py::arg("side"),
        py::arg("rig") = py::none(), py::arg("side_camera") = "auto", py::arg("force") = false,
        py::arg("check_identity") = false,
        "reconstruct(front, side, rig=None, side_camera='auto', force=False, "
        "check_identity=False) -> Model\n\n"
        "A textured 3D face from a front and a side photo, as `orthoface reconstruct`. front, "
        "side: numpy uint8 H x W x 3 arrays in BGR order (as cv2.imread gives) or str / "
        "os.PathLike paths of image files. rig: None (the ideal rig, scale estimated from an "
        "average head; the report says so) or the path of a rig YAML (`orthoface simulate`'s "
        "rig.yaml, `orthoface calibrate`) for true scale. side_camera: 'auto', 'left' or "
        "'right' (`--side-camera`). A pair the input check refuses raises ValueError('input "
        "check NAME: ...'); force=True models it anyway with the failures first in "
        "report['warnings'] (`--force`). check_identity=True also compares the front photo's "
        "face with the model's turned views (`--check-identity`; about 1 s more; RuntimeError "
        "without the face-recognition weights).");
  m.def("load", &load_model, py::arg("dir"),
        "load(dir) -> Model\n\nReads a reconstruction folder (Model.save or `orthoface "
        "reconstruct --out`). Its mesh is welded where the texture atlas split it and has no "
        "texture (views texture it from the photos).");
  m.def("render", &render_view, py::arg("model"), py::arg("yaw") = 30.0, py::arg("pitch") = 0.0,
        py::arg("background") = "photo", py::arg("head") = "whole", py::arg("size") = py::none(),
        py::arg("blend") = "view", py::arg("unseen") = py::none(), py::arg("equalize") = true,
        py::arg("float_textures") = true,
        "render(model, yaw=30, pitch=0, background='photo', head='whole', size=None, "
        "blend='view', unseen=None, equalize=True, float_textures=True) -> numpy array\n\n"
        "A new view of the model, as `orthoface render`: H x W x 3 uint8 BGR, or H x W x 4 BGRA "
        "(alpha = the head) for background='transparent'. yaw: degrees, -180..180, 0 = the front "
        "photo's view, > 0 turns the view toward the subject's left (report "
        "'photographed_side_yaw_sign' says which sign shows the photographed side). pitch: "
        "-89..89, > 0 looks from above. background: 'photo' (the front photo's scene, the head "
        "removed), 'transparent', 'black', 'white', 'grey', '#RRGGBB' or 'R,G,B'. head: 'whole' "
        "(head, hair, ears, neck) or 'face'. size: None (the front photo's) or (width, height), "
        "each 1..8192. blend: 'view', 'pick' or 'weighted'. unseen: None (mirrored view where "
        "the landmarks allow, else the front photo), 'view', 'texture' or 'front'. equalize / "
        "float_textures: as --no-equalize / --no-float when False.");
  m.def(
      "load_mesh", [](const py::object& path) { return mesh_from(path, "mesh"); }, py::arg("path"),
      "load_mesh(path) -> Mesh\n\nReads a mesh file (.obj, .ply, .gltf, .glb).");
  m.def("features", &features_dict, py::arg("mesh"), py::arg("neighbourhood") = 0.03,
        "features(mesh, neighbourhood=0.03) -> dict\n\n"
        "Seed 000's MPEG-4 feature points of a head mesh, as `orthoface features` writes them to "
        "features.json: 'key_vertices' (P1_ear_left, P2_ear_right, P4_nose_tip: {'vertex', "
        "'position'} or None; P3_ear_midpoint), 'axes' and 'symmetry_plane' (when the ears were "
        "found), 'feature_points' (list of {'name', 'description', 'vertex', 'position'}) and "
        "'missing' (one line per point not found). mesh: a Mesh. neighbourhood: ratio radius as "
        "a fraction of the mesh size, 0.001..0.45.");
  m.def("similarity", &similarity_dict, py::arg("a"), py::arg("b"), py::arg("geodesics") = 16,
        py::arg("radius") = 80.0,
        "similarity(a, b, geodesics=16, radius=80) -> dict\n\n"
        "Seed 003 face similarity of two meshes in the standard pose (+z out of the face, +y "
        "up), as `orthoface similarity A B` prints it: {'mean', 'gaussian', 'shape_index', "
        "'curvedness'} (|correlation| in [0, 1], NaN for a metric constant on a face) and "
        "'warnings'. a, b: Mesh objects or mesh paths. geodesics: radial geodesics, 3..360; "
        "radius: outermost iso-geodesic in mesh units.");
  m.def(
      "read_image",
      [](const py::object& path) {
        return image_array(read_colour_image(path_of(path, "image"), "image"));
      },
      py::arg("path"),
      "read_image(path) -> numpy array\n\nAn image file as H x W x 3 uint8 BGR (cv2.imread's "
      "colour mode). RuntimeError when the file is missing or not a readable image.");
}
