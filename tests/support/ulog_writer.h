// A PX4 ULog of one topic written from arrays, for the tests of the commands that read ULogs:
// the real logs in ../shared/testdata are seconds long, too short to calibrate.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

namespace gyrodrift::test {

// Writes `path`: a ULog (version 1) whose sensor_gyro instance `instance` holds one sample per
// row: timestamp (time_s in microseconds, rounded), device_id, x, y, z (rad/s, float) and
// temperature (degC, float), with PX4's field types.
void WriteSensorGyroUlog(const std::string& path, const Eigen::VectorXd& time_s,
                         const Eigen::MatrixXd& xyz_rads, const Eigen::VectorXd& temperature_c,
                         std::uint32_t device_id, int instance = 0);

}  // namespace gyrodrift::test
