#pragma once
/// \file mitigation.hpp
/// Umbrella header of Ke & Wu 2011's NLOS mitigation (papers/ke-wu2011-qp-ekf.md): the box-QP adapter,
/// the Sec. 3 bias estimation, the proposed QP-bias EKF and the bias-augmented ("iterated NLOS") EKF.
/// The default QP solver needs proxsuite (link nlosloc::qp, which defines NLOSLOC_HAVE_PROXSUITE).
#include "nlosloc/mitigation/bias_augmented_ekf.hpp"
#include "nlosloc/mitigation/bias_estimation.hpp"
#include "nlosloc/mitigation/box_qp.hpp"
#include "nlosloc/mitigation/box_qp_proxsuite.hpp"
#include "nlosloc/mitigation/qp_bias_ekf.hpp"
