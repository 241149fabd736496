#include "analysis/similarity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "sim/head.h"
#include "tests/analysis/analysis_test_meshes.h"

namespace orthoface::analysis {
namespace {

mesh::TriMesh head_mesh(int seed, int triangles) {
  sim::HeadOptions o;
  o.target_triangles = triangles;
  return sim::make_head(sim::head_params(seed), o).mesh;
}

// Seed 003 §7.1.1: F_m = (1 - lambda) F1 + lambda F2; similarity to F1 falls as lambda grows.
TEST(Similarity, MorphSequenceFallsMonotonically) {
  const mesh::TriMesh f1 = head_mesh(1, 4000), f2 = head_mesh(2, 4000);
  ASSERT_EQ(f1.vertices.size(), f2.vertices.size());
  const FaceSignature s1 = face_signature(f1);
  EXPECT_EQ(s1.mean.size(), 8u * 16u);
  SimilarityScores prev{1, 1, 1, 1};
  for (double lambda : {0.25, 0.5, 0.75, 1.0}) {
    mesh::TriMesh m = f1;
    for (size_t i = 0; i < m.vertices.size(); ++i)
      m.vertices[i] = (1 - lambda) * f1.vertices[i] + lambda * f2.vertices[i];
    const SimilarityScores s = similarity(s1, face_signature(m));
    EXPECT_LT(s.mean, prev.mean) << lambda;
    EXPECT_LT(s.gaussian, prev.gaussian) << lambda;
    EXPECT_LT(s.shape_index, prev.shape_index) << lambda;
    EXPECT_LT(s.curvedness, prev.curvedness) << lambda;
    prev = s;
  }
  const SimilarityScores self = similarity(s1, s1);
  EXPECT_DOUBLE_EQ(self.shape_index, 1.0);
}

// The ring weights are per vertex ring, so density matters: 8k vs 16k triangles of one head
// beat two different heads on the shape index (measured 0.842 vs 0.799); 4k vs 16k does not.
TEST(Similarity, SameHeadAtTwoResolutionsBeatsDifferentHeads) {
  const SimilarityScores same =
      similarity(face_signature(head_mesh(1, 8000)), face_signature(head_mesh(1, 16000)));
  const SimilarityScores other =
      similarity(face_signature(head_mesh(1, 8000)), face_signature(head_mesh(5, 8000)));
  EXPECT_GT(same.shape_index, other.shape_index);
  EXPECT_GT(same.mean, other.mean);
}

TEST(Similarity, SphereMetricsAreConstantSoScoresAreUndefined) {
  const FaceSignature s = face_signature(testing::icosphere(4, 100.0));
  EXPECT_TRUE(std::isnan(similarity(s, s).shape_index));
}

// signature_problem says why a score would be undefined; a head has none, and two heads that
// pass score finite numbers in [0, 1].
TEST(Similarity, SignatureProblemNamesWhatMakesAScoreUndefined) {
  const FaceSignature sphere = face_signature(testing::icosphere(4, 100.0));
  EXPECT_NE(signature_problem(sphere).find("the same at every network point"), std::string::npos)
      << signature_problem(sphere);
  EXPECT_EQ(signature_problem(FaceSignature{}), "no network points");
  const FaceSignature a = face_signature(head_mesh(1, 4000)),
                      b = face_signature(head_mesh(2, 4000));
  EXPECT_EQ(signature_problem(a), "");
  EXPECT_EQ(signature_problem(b), "");
  for (const SimilarityScores& s : {similarity(a, b), similarity(a, a)})
    for (double v : {s.mean, s.gaussian, s.shape_index, s.curvedness}) {
      EXPECT_TRUE(std::isfinite(v));
      EXPECT_GE(v, 0.0);
      EXPECT_LE(v, 1.0);
    }
  EXPECT_DOUBLE_EQ(similarity(a, a).shape_index, 1.0);
  FaceSignature nan = a;
  nan.curvedness[3] = std::nan("");
  EXPECT_NE(signature_problem(nan).find("curvedness is not finite"), std::string::npos);
  FaceSignature short_metric = a;
  short_metric.gaussian.pop_back();
  EXPECT_NE(signature_problem(short_metric).find("Gaussian curvature has"), std::string::npos);
  FaceSignature flat = a;  // a constant metric beside varying ones
  std::fill(flat.mean.begin(), flat.mean.end(), 0.01);
  EXPECT_NE(signature_problem(flat).find("mean curvature is the same"), std::string::npos);
  EXPECT_TRUE(std::isnan(similarity(flat, a).mean));
}

TEST(Similarity, OpenMeshLimitsTheRadiusAndBadInputThrows) {
  mesh::TriMesh grid =
      testing::plane_grid(40, 2.0);  // 80 mm square, nose tip = a bump at the centre
  for (auto& v : grid.vertices)
    v.z() = 20.0 * std::exp(-((v.x() - 40) * (v.x() - 40) + (v.y() - 40) * (v.y() - 40)) / 200.0);
  const FaceSignature s = face_signature(grid);
  EXPECT_FALSE(s.warnings.empty());
  EXPECT_LT(s.width * 8, 60.0);  // boundary at 40 mm in x / y, a little more over the bump
  EXPECT_GT(s.width * 8, 40.0);
  SimilarityOptions o;
  o.iso_geodesics = 4;
  EXPECT_THROW(similarity(s, face_signature(grid, o)), std::invalid_argument);
  o = {};
  o.radial_geodesics = 2;
  EXPECT_THROW(face_signature(grid, o), std::invalid_argument);
  o = {};
  o.up_axis = o.view_axis;
  EXPECT_THROW(face_signature(grid, o), std::invalid_argument);
  EXPECT_THROW(face_signature(mesh::TriMesh{}), std::invalid_argument);
  // A mesh whose highest point is on its boundary has no room for a network.
  mesh::TriMesh ramp = testing::plane_grid(10, 1.0);
  for (auto& v : ramp.vertices) v.z() = v.x();
  EXPECT_THROW(face_signature(ramp), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::analysis
