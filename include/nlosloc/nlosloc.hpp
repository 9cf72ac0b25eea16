#pragma once
/// \file nlosloc.hpp
/// Umbrella header: everything except the bench scenarios (include nlosloc/sim/registry.hpp for those).
#include "nlosloc/core/cholesky.hpp"
#include "nlosloc/core/ensure.hpp"
#include "nlosloc/core/gaussian.hpp"
#include "nlosloc/core/logsumexp.hpp"
#include "nlosloc/core/random.hpp"
#include "nlosloc/core/sigma_points.hpp"
#include "nlosloc/core/types.hpp"
#include "nlosloc/filters/ekf.hpp"
#include "nlosloc/filters/kf.hpp"
#include "nlosloc/filters/ukf.hpp"
#include "nlosloc/models/measurement.hpp"
#include "nlosloc/models/motion.hpp"
#include "nlosloc/models/noise.hpp"
