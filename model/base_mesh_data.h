#pragma once

// The generic head shape behind base_mesh(): constants generated offline (model_bench gen-base)
// from the project's own average simulated head, so model/ does not link sim/ (not public API).
namespace orthoface::model::detail {

struct GenericLandmarkPosition {
  const char* name;
  double x, y, z;
};

extern const int kGenericRows;
extern const int kGenericHalfRays;
extern const double kGenericTop, kGenericBottom;
extern const double kGenericContour[][46][2];
extern const GenericLandmarkPosition kGenericLandmarks[];
extern const int kGenericLandmarkCount;

}  // namespace orthoface::model::detail
