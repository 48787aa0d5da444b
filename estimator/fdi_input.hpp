// What the fault detector sees of one sample the DriftLess filter has just taken: the outputs,
// the box-from-sensor rotations at the platforms' rest angles, whether the residual is valid
// (both platforms at rest, the filter inside a standstill) and the filter's estimate with its
// covariance. One builder for every stream that runs the FDI beside the filter: the studies'
// fault sweep and the live loop of the HIL bridge (docs/fdi.md, docs/hil.md).
#pragma once

#include "estimator/fdi.hpp"
#include "estimator/filter.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {

/// The FdiInput of sample `s` after `filter.push(s)` returned `status`. The residual is valid
/// (at_rest) when the filter took the sample into a standstill (accumulating, updated or gated)
/// and both platform angles are known; the rotations are the filter's own (hinge or calibrated).
FdiInput fdi_input(const Sample& s, PushStatus status, const DriftlessFilter& filter);

}  // namespace driftless::est
