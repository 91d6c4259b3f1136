#include "support/ulog_writer.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace gyrodrift::test {
namespace {

void Put(std::vector<char>& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

void PutFloat(std::vector<char>& out, double value) {
  const float f = static_cast<float>(value);
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, 4);
  Put(out, bits, 4);
}

void Message(std::vector<char>& out, char type, const std::vector<char>& payload) {
  Put(out, payload.size(), 2);
  out.push_back(type);
  out.insert(out.end(), payload.begin(), payload.end());
}

}  // namespace

void WriteSensorGyroUlog(const std::string& path, const Eigen::VectorXd& time_s,
                         const Eigen::MatrixXd& xyz_rads, const Eigen::VectorXd& temperature_c,
                         std::uint32_t device_id, int instance) {
  std::vector<char> out{'U', 'L', 'o', 'g', 0x01, 0x12, 0x35, 0x01};
  Put(out, 0, 8);
  const std::string format =
      "sensor_gyro:uint64_t timestamp;uint32_t device_id;float x;float y;float z;"
      "float temperature;";
  Message(out, 'F', {format.begin(), format.end()});
  std::vector<char> subscribe;
  Put(subscribe, static_cast<std::uint64_t>(instance), 1);
  Put(subscribe, 3, 2);  // message id
  const std::string topic = "sensor_gyro";
  subscribe.insert(subscribe.end(), topic.begin(), topic.end());
  Message(out, 'A', subscribe);
  for (Eigen::Index i = 0; i < time_s.size(); ++i) {
    std::vector<char> d;
    Put(d, 3, 2);
    Put(d, static_cast<std::uint64_t>(std::llround(time_s[i] * 1e6)), 8);
    Put(d, device_id, 4);
    for (int axis = 0; axis < 3; ++axis) PutFloat(d, xyz_rads(i, axis));
    PutFloat(d, temperature_c[i]);
    Message(out, 'D', d);
  }
  std::ofstream file(path, std::ios::binary);
  file.write(out.data(), static_cast<std::streamsize>(out.size()));
  if (!file) throw std::runtime_error("cannot write " + path);
}

}  // namespace gyrodrift::test
