// The C++ side of bench/python/bench_decompose.py: times decomposition::Decompose on a signal read
// from a raw float64 file, with the options the script passes, and prints one JSON line
// {"seconds": [...], "imfs": K}. The script times gyrodrift.decompose on the same signal and
// options; the difference of the medians is the binding's overhead (conversion in and out, the
// GIL release).
//   decompose_timing SIGNAL.f64 METHOD ENSEMBLE SEED THREADS REPEATS [STOP FIXED_SIFTS]
#include <Eigen/Core>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "gyrodrift/decomposition/decomposition.h"

int main(int argc, char** argv) {
  if (argc != 7 && argc != 9) {
    std::fprintf(stderr, "usage: %s SIGNAL.f64 METHOD ENSEMBLE SEED THREADS REPEATS [STOP FIXED_SIFTS]\n",
                 argv[0]);
    return 2;
  }
  std::ifstream in(argv[1], std::ios::binary | std::ios::ate);
  if (!in) {
    std::fprintf(stderr, "%s: cannot read\n", argv[1]);
    return 4;
  }
  const auto bytes = static_cast<Eigen::Index>(in.tellg());
  Eigen::VectorXd x(bytes / static_cast<Eigen::Index>(sizeof(double)));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(x.data()), static_cast<std::streamsize>(x.size() * sizeof(double)));
  namespace dec = gyrodrift::decomposition;
  dec::DecompositionOptions o;
  o.method = dec::MethodFromString(argv[2]);
  o.ensemble_size = std::atoi(argv[3]);
  o.seed = std::strtoull(argv[4], nullptr, 10);
  dec::DecompositionContext context;
  context.execution.threads = std::atoi(argv[5]);
  const int repeats = std::atoi(argv[6]);
  if (argc == 9) {
    o.sifting.stop_rule = dec::StopRuleFromString(argv[7]);
    o.sifting.fixed_sifts = std::atoi(argv[8]);
  }
  std::vector<double> seconds;
  int imfs = 0;
  for (int i = 0; i < repeats; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const dec::Decomposition d = dec::Decompose(x, o, context);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    imfs = d.num_imfs();
  }
  std::printf("{\"seconds\": [");
  for (size_t i = 0; i < seconds.size(); ++i) std::printf("%s%.9g", i ? ", " : "", seconds[i]);
  std::printf("], \"imfs\": %d}\n", imfs);
  return 0;
}
