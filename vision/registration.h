#pragma once
// Registration of the side photo to the front photo (issue: real photos are never taken at one
// height, and a head nods between two shots): which side-photo row shows the height of a
// front-photo row.

#include "vision/observation.h"

namespace orthoface::vision {

// Side rows as a linear function of front rows, side = a * front + b (observation pixels).
struct RowMap {
  double a = 1, b = 0;
  int pairs = 0;             // pairs the map was fitted to
  bool independent = false;  // from features found in each photo on its own
};

// The map from the midline features (nasion, nose tip, subnasale, lips, chin) seen in both
// views. Pairs whose front row was copied from the profile (method "...profile-row": the seed's
// filters) register nothing, and a side feature placed by the position model is a guess; with
// three or more pairs left, a least-median-of-squares line (scale 0.8..1.25) refined by least
// squares on the pairs within 3 px of it (`independent`). Otherwise the least-squares line
// through all pairs (scale 1 when they span less than ~20 px), the identity with none.
RowMap side_row_map(const FaceObservation& observation);

}  // namespace orthoface::vision
