#include "gyrodrift/common/execution.h"

#include <string>

#include "gyrodrift/common/check.h"

namespace gyrodrift {

void ValidateThreads(int threads) {
  if (threads < 0 || threads > 1024) {
    ThrowOption("threads", std::to_string(threads), "an integer in [0, 1024] (0 = all cores)");
  }
}

void Execution::Validate() const { ValidateThreads(threads); }

}  // namespace gyrodrift
