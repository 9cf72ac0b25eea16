#pragma once
/// \file snapshot.hpp
/// Per-epoch baselines of Huerta et al. 2009 Sec. VI: MLE-LOS, CHEN, CONG, URR, and their Estimator adapter.
#include "nlosloc/snapshot/chen.hpp"
#include "nlosloc/snapshot/cong.hpp"
#include "nlosloc/snapshot/estimator.hpp"
#include "nlosloc/snapshot/gauss_newton.hpp"
#include "nlosloc/snapshot/mle_los.hpp"
#include "nlosloc/snapshot/result.hpp"
#include "nlosloc/snapshot/urruela.hpp"
