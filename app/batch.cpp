// orthoface-batch: many front/side pairs or an all-pairs similarity matrix, split over MPI
// ranks (rank 0 gathers and draws the progress bar). A separate executable so the main
// `orthoface` binary never loads MPI; it runs single-process without mpirun (singleton init).
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "analysis/similarity.h"
#include "app/cli.h"
#include "capture/camera_model.h"
#include "io/atomic_file.h"
#include "mesh/mesh_io.h"
#include "reconstruct/reconstruction.h"
#include "vision/image_prep.h"

namespace fs = std::filesystem;
using namespace orthoface;

namespace {

constexpr int kTagDone = 1, kTagErrors = 2;

const char* kUsage =
    "usage: orthoface-batch pairs DIR -o OUT [--force] [--check-identity]\n"
    "                                          (DIR/<name>/front.* + side.* [+ rig.yaml]\n"
    "                                          [+ front_background.*, side_background.*: clean\n"
    "                                          plates]; PNG, JPEG, BMP, TIFF, WebP, PPM/PGM; a\n"
    "                                          pair the input check refuses is a failed item,\n"
    "                                          with --force modelled; --check-identity also\n"
    "                                          refuses a side photo of someone else, as\n"
    "                                          `reconstruct --check-identity` does)\n"
    "       orthoface-batch similarity DIR -o OUT   (all .obj .ply .off .glb meshes in DIR)\n"
    "       run under mpirun -np N to split the work; rank 0 gathers and reports progress.\n"
    "       Every item is tried; OUT/batch_report.json gives each one's result and, for a failed\n"
    "       one, why. Exit 0 when all succeed, 1 when any failed (after all were tried), 2 on\n"
    "       bad arguments.\n";

// The photo named `stem` (front / side, any case) in an item folder: one file with an image
// extension OpenCV reads. Throws std::runtime_error naming what is missing or ambiguous; an
// `optional` one that is missing gives an empty path.
fs::path item_photo(const fs::path& folder, const std::string& stem, bool optional = false) {
  static const char* kExts[] = {".png",  ".jpg",  ".jpeg", ".bmp", ".tif",
                                ".tiff", ".webp", ".ppm",  ".pgm"};
  std::vector<fs::path> found;
  for (const auto& e : fs::directory_iterator(folder)) {
    std::string name = e.path().filename().string(), ext = e.path().extension().string();
    std::transform(name.begin(), name.end(), name.begin(), ::tolower);
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (!e.is_regular_file() || name != stem + ext) continue;
    for (const char* x : kExts)
      if (ext == x) found.push_back(e.path());
  }
  if (found.empty() && optional) return {};
  if (found.empty())
    throw std::runtime_error("no " + stem + " image (" + stem + ".png, .jpg, ...)");
  if (found.size() > 1)
    throw std::runtime_error("more than one " + stem + " image (" + found[0].filename().string() +
                             ", " + found[1].filename().string() + ")");
  return found[0];
}

// Each rank's error messages (item index -> text) gathered on rank 0.
void gather_errors(std::vector<std::string>& errors, int rank, int size) {
  if (rank != 0) {
    nlohmann::json j = nlohmann::json::object();
    for (size_t i = 0; i < errors.size(); ++i)
      if (!errors[i].empty()) j[std::to_string(i)] = errors[i];
    const std::string text = j.dump();
    MPI_Send(text.data(), int(text.size()), MPI_CHAR, 0, kTagErrors, MPI_COMM_WORLD);
    return;
  }
  for (int r = 1; r < size; ++r) {
    MPI_Status st;
    MPI_Probe(r, kTagErrors, MPI_COMM_WORLD, &st);
    int count = 0;
    MPI_Get_count(&st, MPI_CHAR, &count);
    std::string text(size_t(count), '\0');
    MPI_Recv(text.data(), count, MPI_CHAR, r, kTagErrors, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    const nlohmann::json j = nlohmann::json::parse(text);  // outlives the loop over its items
    for (const auto& [i, msg] : j.items()) errors.at(std::stoul(i)) = msg.get<std::string>();
  }
}

// Rank 0: draws "[#####.....] done/total" from its own count plus messages from the others.
struct Progress {
  int total = 0, done = 0;
  void draw() const {
    const int width = 40, filled = total ? width * done / total : width;
    std::fprintf(stderr, "\r[%s%s] %d/%d", std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), done, total);
    if (done == total) std::fprintf(stderr, "\n");
  }
  void poll() {
    int flag = 1;
    while (flag) {
      MPI_Status st;
      MPI_Iprobe(MPI_ANY_SOURCE, kTagDone, MPI_COMM_WORLD, &flag, &st);
      if (!flag) break;
      int one = 0;
      MPI_Recv(&one, 1, MPI_INT, st.MPI_SOURCE, kTagDone, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      ++done;
      draw();
    }
  }
};

void item_done(int rank, Progress& p) {
  if (rank == 0) {
    ++p.done;
    p.draw();
    p.poll();
  } else {
    int one = 1;
    MPI_Send(&one, 1, MPI_INT, 0, kTagDone, MPI_COMM_WORLD);
  }
}

// Items i with i % size == rank.
std::vector<int> my_items(int n, int rank, int size) {
  std::vector<int> out;
  for (int i = rank; i < n; i += size) out.push_back(i);
  return out;
}

// Per item: 1 = ok, 0 = failed, and the milliseconds it took; gathered on rank 0 by sum.
void gather_status(std::vector<double>& status, std::vector<double>& ms) {
  std::vector<double> s2(status.size()), m2(ms.size());
  MPI_Reduce(status.data(), s2.data(), int(status.size()), MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  MPI_Reduce(ms.data(), m2.data(), int(ms.size()), MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  status.swap(s2), ms.swap(m2);
}

// The input check a refused pair failed ("input check NAME: ..."), or "".
std::string refused_by(const std::string& error) {
  const std::string prefix = "input check ";
  if (error.rfind(prefix, 0) != 0) return {};
  const size_t colon = error.find(':', prefix.size());
  return colon == std::string::npos ? std::string()
                                    : error.substr(prefix.size(), colon - prefix.size());
}

int run_pairs(const fs::path& dir, const fs::path& out, bool force, bool check_identity, int rank,
              int size) {
  std::vector<fs::path> items;  // every sub-folder: one without its photos is a failed item
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_directory() && !(fs::exists(out) && fs::equivalent(e.path(), out)))
      items.push_back(e.path());
  std::sort(items.begin(), items.end());
  const int n = int(items.size());
  if (n == 0) throw std::runtime_error(dir.string() + ": no <name>/ folders with front + side");
  Progress progress{n, 0};
  std::vector<double> status(n, 0.0), ms(n, 0.0);
  std::vector<std::string> errors(n);
  for (int i : my_items(n, rank, size)) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      reconstruct::ReconstructOptions o;
      o.force = force;
      o.check_identity = check_identity;
      if (fs::exists(items[i] / "rig.yaml"))
        o.rig = capture::read_rig((items[i] / "rig.yaml").string());
      // The photos, then the clean plates (the cameras' empty scenes) when the item has them,
      // read as `orthoface reconstruct` reads them (grey, 16-bit, RGBA converted; sizes checked).
      const char* stems[] = {"front", "side", "front_background", "side_background"};
      cv::Mat photos[4];
      std::string names;  // the files a failure of the pair is about
      for (int k = 0; k < 4; ++k) {
        const fs::path p = item_photo(items[i], stems[k], k >= 2);
        if (p.empty()) continue;
        photos[k] = vision::read_image(p.string());
        names += (names.empty() ? "" : ", ") + p.filename().string();
      }
      o.observe.background_front = photos[2];
      o.observe.background_side = photos[3];
      reconstruct::Reconstruction r;
      try {
        r = reconstruct::from_photos(photos[0], photos[1], o);
      } catch (const reconstruct::InputRefused& e) {  // keeps "input check NAME:" first
        throw reconstruct::InputRefused(e.check(), names + ": " + e.problem());
      } catch (const std::exception& e) {
        throw std::runtime_error(names + ": " + e.what());
      }
      reconstruct::write_reconstruction(r, (out / items[i].filename()).string());
      status[i] = 1.0;
    } catch (const std::exception& e) {
      errors[i] = app::one_line(e.what());
      std::fprintf(stderr, "\nerror: %s: %s\n", items[i].string().c_str(), errors[i].c_str());
    }
    ms[i] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    item_done(rank, progress);
  }
  gather_status(status, ms);
  gather_errors(errors, rank, size);
  if (rank != 0) return 0;
  while (progress.done < n) progress.poll();
  nlohmann::json j{{"ranks", size}, {"pairs", n}};
  int ok = 0;
  nlohmann::json refused = nlohmann::json::object();  // input check -> pairs it refused
  for (int i = 0; i < n; ++i) {
    ok += status[i] > 0.5;
    nlohmann::json item{
        {"name", items[i].filename().string()}, {"ok", status[i] > 0.5}, {"ms", ms[i]}};
    if (status[i] <= 0.5) {
      item["error"] = errors[i];
      const std::string check = refused_by(errors[i]);
      if (!check.empty()) {
        item["refused_by"] = check;
        refused[check] = refused.value(check, 0) + 1;
      }
    }
    j["items"].push_back(item);
  }
  j["ok"] = ok;
  j["failed"] = n - ok;
  j["refused_by_input_check"] = refused;
  io::write_text_atomically((out / "batch_report.json").string(), j.dump(2) + "\n");
  std::printf("batch: %d / %d pairs reconstructed on %d rank(s) -> %s\n", ok, n, size, out.c_str());
  return ok == n ? 0 : 1;
}

// The matrices hold the meshes that gave a usable signature; one that failed (unreadable, no
// surface around the nose tip, a metric that is the same everywhere) is an error line naming it
// and an entry in batch_report.json, never a NaN row. Every output is written together or not
// at all.
int run_similarity_matrix(const fs::path& dir, const fs::path& out, int rank, int size) {
  std::vector<fs::path> items;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (e.is_regular_file() && (ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".glb"))
      items.push_back(e.path());
  }
  std::sort(items.begin(), items.end());
  const int n = int(items.size());
  if (n < 2) throw std::runtime_error(dir.string() + ": needs at least two meshes");
  const analysis::SimilarityOptions options;
  const size_t len = size_t(options.iso_geodesics) * size_t(options.radial_geodesics);
  // Each rank builds the signatures of its meshes; rank 0 gets all metric vectors (4 x len).
  std::vector<double> metrics(size_t(n) * 4 * len, 0.0), status(n, 0.0), ms(n, 0.0);
  std::vector<std::string> errors(n);
  Progress progress{n, 0};
  for (int i : my_items(n, rank, size)) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      const auto s = analysis::face_signature(mesh::read_mesh(items[i].string()), options);
      if (s.mean.size() != len)
        throw std::runtime_error("its network has " + std::to_string(s.mean.size()) +
                                 " points, not " + std::to_string(len));
      const std::string problem = analysis::signature_problem(s);
      if (!problem.empty()) throw std::runtime_error(problem);
      const std::vector<double>* parts[] = {&s.mean, &s.gaussian, &s.shape_index, &s.curvedness};
      for (int k = 0; k < 4; ++k)
        std::copy(parts[k]->begin(), parts[k]->end(), metrics.begin() + (size_t(i) * 4 + k) * len);
      status[i] = 1.0;
    } catch (const std::exception& e) {
      // A reader's message names the file already.
      const std::string name = items[i].string(), what = e.what();
      errors[i] = what;
      std::fprintf(stderr, "\nerror: %s\n",
                   (what.rfind(name, 0) == 0 ? what : name + ": " + what).c_str());
    }
    ms[i] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    item_done(rank, progress);
  }
  std::vector<double> all(metrics.size());
  MPI_Reduce(metrics.data(), all.data(), int(all.size()), MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  gather_status(status, ms);
  gather_errors(errors, rank, size);
  if (rank != 0) return 0;
  while (progress.done < n) progress.poll();
  std::vector<int> good;  // the meshes in the matrices
  for (int i = 0; i < n; ++i)
    if (status[i] > 0.5) good.push_back(i);
  nlohmann::json j{{"ranks", size}, {"meshes", n}};
  for (int i = 0; i < n; ++i) {
    nlohmann::json item{
        {"name", items[i].filename().string()}, {"ok", status[i] > 0.5}, {"ms", ms[i]}};
    if (status[i] <= 0.5) item["error"] = errors[i];
    j["items"].push_back(item);
  }
  j["ok"] = good.size();
  j["failed"] = n - int(good.size());
  const char* names[] = {"mean", "gaussian", "shape_index", "curvedness"};
  std::vector<std::string> csvs(4);
  if (good.size() >= 2) {
    for (int k = 0; k < 4; ++k) {
      std::ostringstream csv;
      csv << "mesh";
      for (int i : good) csv << "," << items[i].filename().string();
      csv << "\n";
      auto signature = [&](int m) {
        analysis::FaceSignature s;
        s.mean.assign(all.begin() + (size_t(m) * 4 + k) * len,
                      all.begin() + (size_t(m) * 4 + k + 1) * len);
        s.gaussian = s.shape_index = s.curvedness = s.mean;
        return s;
      };
      for (int a : good) {
        csv << items[a].filename().string();
        for (int b : good) {
          const double v = analysis::similarity(signature(a), signature(b)).mean;
          if (!std::isfinite(v))  // signature_problem rules this out; never written as NaN
            throw std::runtime_error("mesh " + items[a].string() + " and mesh " +
                                     items[b].string() + ": " + names[k] +
                                     " similarity is not a number");
          csv << "," << v;
        }
        csv << "\n";
      }
      csvs[k] = csv.str();
    }
  }
  io::FileGroup outputs;  // the matrices and the report, or none of them (a full disk)
  for (int k = 0; k < 4 && good.size() >= 2; ++k)
    io::write_text_atomically((out / (std::string("similarity_") + names[k] + ".csv")).string(),
                              csvs[k]);
  io::write_text_atomically((out / "batch_report.json").string(), j.dump(2) + "\n");
  outputs.commit();
  if (good.size() < 2)
    std::printf("batch: %zu / %d signatures on %d rank(s); no matrix (it needs two) -> %s\n",
                good.size(), n, size, (out / "batch_report.json").c_str());
  else
    std::printf("batch: %zu / %d signatures on %d rank(s) -> %s/similarity_*.csv\n", good.size(), n,
                size, out.c_str());
  return int(good.size()) == n ? 0 : 1;
}

// Open MPI 4 keeps a session directory per job under one shared folder of the temporary
// directory; single processes started side by side (a script's loop, a test suite) race on
// creating and removing that folder, and the loser's MPI_Init fails (open-mpi/ompi#8510). Started
// without mpirun, each process gets a folder of its own (removed at exit); under mpirun, or when
// the user sets orte_tmpdir_base, Open MPI's own choice stands.
class OwnSessionFolder {
 public:
  OwnSessionFolder() {
    if (std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("OMPI_MCA_orte_tmpdir_base")) return;
    const char* tmp = std::getenv("TMPDIR");
    std::string templ = std::string(tmp && *tmp ? tmp : "/tmp") + "/orthoface-batch-XXXXXX";
    if (!mkdtemp(templ.data())) return;  // Open MPI's default then; its own error if that fails
    dir_ = templ;
    setenv("OMPI_MCA_orte_tmpdir_base", dir_.c_str(), 1);
  }
  ~OwnSessionFolder() {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  OwnSessionFolder(const OwnSessionFolder&) = delete;
  OwnSessionFolder& operator=(const OwnSessionFolder&) = delete;

 private:
  std::string dir_;
};

}  // namespace

int main(int argc, char** argv) {
  const OwnSessionFolder session_folder;
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int rc = 0;
  try {
    if (argc == 2 && (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h"))) {
      if (rank == 0) std::printf("%s", kUsage);
    } else if (argc < 5 || std::strcmp(argv[3], "-o") != 0 ||
               (std::strcmp(argv[1], "pairs") && std::strcmp(argv[1], "similarity")) ||
               (argc > 5 && std::strcmp(argv[1], "pairs"))) {
      throw std::invalid_argument(std::string("bad arguments\n") + kUsage);
    } else {
      bool force = false, check_identity = false;
      for (int k = 5; k < argc; ++k) {
        if (!std::strcmp(argv[k], "--force"))
          force = true;
        else if (!std::strcmp(argv[k], "--check-identity"))
          check_identity = true;
        else
          throw std::invalid_argument(std::string("unknown option ") + argv[k] + "\n" + kUsage);
      }
      const fs::path dir = argv[2], out = argv[4];
      if (!fs::is_directory(dir)) throw std::runtime_error(dir.string() + ": not a folder");
      if (rank == 0) fs::create_directories(out);
      MPI_Barrier(MPI_COMM_WORLD);
      rc = !std::strcmp(argv[1], "pairs") ? run_pairs(dir, out, force, check_identity, rank, size)
                                          : run_similarity_matrix(dir, out, rank, size);
    }
  } catch (const std::invalid_argument& e) {
    if (rank == 0) std::fprintf(stderr, "error: %s\n", e.what());
    rc = 2;
  } catch (const std::exception& e) {
    if (rank == 0) std::fprintf(stderr, "error: %s\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
