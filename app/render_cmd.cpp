// orthoface render: new views of a reconstruction folder by texture inheritance (seed 004 §6).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "capture/camera_model.h"
#include "io/atomic_file.h"
#include "mesh/mesh_io.h"
#include "reconstruct/reconstruction.h"
#include "reconstruct/views.h"
#include "render/contact_sheet.h"
#include "render/new_view.h"
#include "render/textured_export.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

Command render_command() {
  return {"render",
          "Render a reconstruction folder (head.obj, front.png, side.png, rig.yaml) from a new "
          "yaw / pitch: every visible surface point takes its colour from the photo it faces "
          "more (pick) or a cosine-weighted mix (weighted), never from a photo that cannot see "
          "it. Without rig.yaml the ideal rig of the photo size (1.6 px/mm) is assumed.",
          "orthoface render DIR --yaw DEG [options] -o view.png   |   orthoface render DIR "
          "--export head.glb",
          {{"yaw", true,
            "DEG  -180..180: 0 = the front photo's view; > 0 turns the view toward the "
            "subject's left (the face seems turned to its own right), < 0 toward the "
            "subject's right, whichever side the side camera stood on; "
            "report.json's photographed_side_yaw_sign says which sign shows the "
            "photographed side"},
           {"pitch", true, "DEG  -89..89, > 0 looks from above (default 0)"},
           {"size", true, "WxH  output size, each side 1..8192 (default: the front photo's)"},
           {"blend", true,
            "MODE  view (default: the photo nearer the new view and better facing), "
            "pick (the photo the surface faces more, seed 004) or weighted"},
           {"background", true,
            "photo (default: the front photo's own scene, the head removed: its clean plate "
            "when reconstruct had --front-background, else inpainted; the lower neck twists "
            "into the photo's unturned body), black, white, grey, #RRGGBB, R,G,B or transparent "
            "(PNG)"},
           {"turntable", true, "N  N views from yaw -90 to 90 (view_yaw<D>.png) + a sheet at -o"},
           {"no-equalize", false, "use the photos' colours as they are"},
           {"no-float", false,
            "blend the photos as projected, pixel by pixel, without aligning them by "
            "optical flow first (floating textures) or blending them band by band"},
           {"unseen", true,
            "SOURCE  the side the side camera never saw, mirrored about the face's mid-plane "
            "(landmarks.json, turned by report.json's head_yaw_deg when the head was modelled "
            "facing front): view (default: a view turned 20 deg or more toward it is drawn "
            "as the mirror image of the opposite view), texture (the side photo mirrored, "
            "blended with the front photo) or front (the front photo alone; also the default's "
            "fallback without landmarks.json)"},
           {"head", true,
            "EXTENT  whole (default: the head, hair, ears and neck from both photos' "
            "silhouettes around the face) or face (the face mesh alone)"},
           {"export", true,
            "FILE  also write the mesh with the inherited texture: .obj (+ .mtl "
            ".png), .glb (texture embedded) or .ply (vertex colours)"},
           {"o", true, "FILE  output image (.png, .jpg, .bmp); replaced if it exists"}},
          1};
}

void write_image(const cv::Mat& image, const fs::path& path) {
  io::write_image_atomically(path.string(), image);
}

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

void check_output_folder(const fs::path& out, const std::string& flag) {
  if (fs::is_directory(out))
    throw std::invalid_argument(flag + " " + out.string() + " is a folder");
  if (out.has_parent_path() && !fs::is_directory(out.parent_path()))
    throw std::invalid_argument(flag + " " + out.string() + ": folder " +
                                out.parent_path().string() + " does not exist");
}

// Refuses an output that would replace one of the reconstruction folder's own files (render
// reads them; a view written over front.png would destroy the model's photo).
void refuse_folder_file(const fs::path& out, const fs::path& dir, const std::string& flag) {
  std::error_code ec;
  for (const char* name : reconstruct::kFolderFiles)
    if (fs::exists(dir / name) && fs::equivalent(out, dir / name, ec))
      throw std::invalid_argument(flag + " " + out.string() + " is the reconstruction's own " +
                                  name + "; write the output elsewhere");
}

void export_mesh(const reconstruct::Reconstruction& f, const fs::path& path, bool equalize) {
  render::InheritOptions o;
  o.equalize = equalize;
  const std::string ext = lower_extension(path);
  if (ext == ".ply") {
    mesh::write_mesh(render::inherit_vertex_colours(f.mesh, f.photo_rig, f.front, f.side, o),
                     path.string());
  } else {
    const mesh::TriMesh m = render::inherit_texture(f.mesh, f.photo_rig, f.front, f.side, o).mesh;
    if (ext == ".glb")
      render::write_glb(m, path.string());
    else
      mesh::write_mesh(m, path.string());
  }
}

}  // namespace

int run_render(int argc, char** argv) {
  const Command cmd = render_command();
  const Args a = parse_args(cmd, argc, argv);
  if (a.help) return print_help(cmd), 0;
  if (a.positional.empty())
    throw std::invalid_argument("render: missing the reconstruction folder DIR");
  const bool view_wanted = a.has("o") || a.has("yaw") || a.has("turntable");
  if (a.has("export")) {
    const fs::path e = a.get("export");
    const std::string ext = lower_extension(e);
    if (ext != ".obj" && ext != ".glb" && ext != ".ply")
      throw std::invalid_argument("--export " + e.string() +
                                  ": expected a .obj, .glb or .ply file");
    check_output_folder(e, "--export");
    refuse_folder_file(e, a.positional[0], "--export");
  }
  if (view_wanted && !a.has("o")) throw std::invalid_argument("render: missing -o FILE");
  if (!view_wanted && !a.has("export"))
    throw std::invalid_argument("render: nothing to do: give --yaw DEG -o FILE or --export FILE");
  const int turntable = a.has("turntable") ? to_int("turntable", a.get("turntable"), 2, 360) : 0;
  if (view_wanted && !a.has("yaw") && !turntable)
    throw std::invalid_argument("render: missing --yaw DEG");
  const double yaw = a.has("yaw") ? to_double("yaw", a.get("yaw"), -180, 180) : 0;
  const double pitch = to_double("pitch", a.get("pitch", "0"), -89, 89);
  reconstruct::ViewOptions vo;
  render::SynthesisOptions& o = vo.synthesis;
  try {
    o.blend = render::parse_blend(a.get("blend", "view"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--blend: ") + e.what());
  }
  o.equalize = !a.has("no-equalize");
  try {
    vo.background = reconstruct::parse_view_background(a.get("background", "photo"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--background: ") + e.what());
  }
  const bool transparent = vo.background.kind == reconstruct::ViewBackground::Kind::Transparent;
  const fs::path out = a.get("o");
  const std::string ext = lower_extension(out);
  if (view_wanted) {
    if (ext != ".png" && ext != ".jpg" && ext != ".jpeg" && ext != ".bmp")
      throw std::invalid_argument("-o " + out.string() + ": expected a .png, .jpg or .bmp file");
    if (transparent && ext != ".png")
      throw std::invalid_argument("--background transparent needs a .png output, not " +
                                  out.string());
    check_output_folder(out, "-o");
    refuse_folder_file(out, a.positional[0], "-o");
  }
  if (a.has("size"))
    std::tie(vo.width, vo.height) = to_size("size", a.get("size"), render::kMaxRenderSize);
  try {
    o.unseen = render::parse_unseen_side(a.get("unseen", "view"));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--unseen: ") + e.what());
  }
  const reconstruct::Reconstruction f = reconstruct::read_reconstruction(
      a.positional[0], {.landmarks = o.unseen != render::UnseenSide::Front});
  io::FileGroup outputs;     // the export and every view, or none of them (a full disk half-way)
  const auto commit = [&] {  // and say what was exported, once it is there
    outputs.commit();
    if (a.has("export")) std::printf("wrote %s\n", a.get("export").c_str());
  };
  if (a.has("export")) export_mesh(f, a.get("export"), o.equalize);
  if (!view_wanted) {
    commit();
    return 0;
  }
  const std::string head = a.get("head", "whole");
  if (head != "whole" && head != "face")
    throw std::invalid_argument("--head: expected whole or face, not '" + head + "'");
  vo.head = head == "face" ? reconstruct::HeadExtent::Face : reconstruct::HeadExtent::Whole;
  o.float_textures = !a.has("no-float");
  // Without landmark pairs the unseen side falls back to the front photo; an explicit --unseen
  // that needs them is refused.
  reconstruct::ViewRenderer views(f, vo);
  if (a.has("unseen") && views.options().synthesis.unseen != o.unseen)
    throw std::invalid_argument("--unseen " + a.get("unseen") + ": " + a.positional[0] +
                                " has no landmarks.json with left / right feature pairs");
  const int w = views.width(), h = views.height();
  const render::SynthesisOptions& used = views.options().synthesis;
  if (!turntable) {
    write_image(views.image(yaw, pitch), out);
    commit();
    std::printf("wrote %s (%dx%d, yaw %.1f, pitch %.1f, %s, unseen side: %s)\n",
                out.string().c_str(), w, h, yaw, pitch, render::blend_name(used.blend),
                render::unseen_side_name(used.unseen));
    return 0;
  }
  std::vector<render::Tile> tiles;
  for (int i = 0; i < turntable; ++i) {
    const double y = -90.0 + 180.0 * i / (turntable - 1);
    const reconstruct::FinishedView r = views.view(y, pitch);
    char name[64];
    // Whole degrees name up to 181 views apart; more views are closer than a degree.
    if (turntable <= 181)
      std::snprintf(name, sizeof(name), "_yaw%+04d", int(std::lround(y)));
    else
      std::snprintf(name, sizeof(name), "_yaw%+06.1f", y);
    const fs::path view = out.parent_path() / (out.stem().string() + name + ext);
    const cv::Mat& shown = r.image;
    write_image(shown, view);
    tiles.push_back({shown.channels() == 3 ? shown : r.view.image,
                     "yaw " + std::to_string(int(std::lround(y)))});
  }
  render::ContactSheetOptions so;
  so.columns = std::min(turntable, 6);
  so.title = "orthoface render " + a.positional[0] + " (" + render::blend_name(o.blend) + ")";
  write_image(render::contact_sheet(tiles, so), out);
  commit();
  std::printf("wrote %d views and the sheet %s\n", turntable, out.string().c_str());
  return 0;
}

}  // namespace orthoface::app
