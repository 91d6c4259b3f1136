// EMD-ELM's own step (fit_steps.h): every IMF and the residue a sub-model of its own, no grouping
// (the baseline METHOD.md section 5 lists beside MS-ELM).
#include <string>

#include "drift/fit_steps.h"

namespace gyrodrift::drift::internal {

decomposition::Decomposition DecomposeForEmdElm(const Eigen::Ref<const Eigen::VectorXd>& y,
                                                const decomposition::DecompositionOptions& dopt,
                                                const decomposition::DecompositionContext& context,
                                                DriftModel& model) {
  decomposition::Decomposition d = decomposition::Decompose(y, dopt, context);
  if (d.num_imfs() > 0) {
    for (int k = 1; k <= d.num_imfs(); ++k) {
      model.sub_models.push_back({"imf" + std::to_string(k), {k}, false, nullptr});
    }
    model.sub_models.push_back({"residue", {}, true, nullptr});
  }
  return d;
}

}  // namespace gyrodrift::drift::internal
