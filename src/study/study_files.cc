// The study's files: CSV renderings of its data and tables, the record, and writing the set.
#include "gyrodrift/study/study_files.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "study_steps.h"

namespace gyrodrift::study {
namespace {

namespace sim = gyrodrift::simulation;
namespace sel = gyrodrift::selection;

std::string SimulationCsv(const sim::SimulationResult& r) {
  return io::RenderCsv({{"time_s", r.time_s},
                        {"rate_dph", r.rate_dph},
                        {"temperature_c", r.temperature_c},
                        {"drift_dph", r.drift_dph},
                        {"shupe_dph", r.shupe_dph},
                        {"stress_dph", r.stress_dph},
                        {"bias_dph", r.bias_dph},
                        {"noise_dph", r.noise_dph},
                        {"chamber_c", r.chamber_c},
                        {"case_c", r.case_c},
                        {"coil_mean_c", r.coil_mean_c}});
}

std::string ImfsCsv(const StudyResult& s) {
  std::vector<io::CsvColumn> c{{"time_s", s.time_h * 3600.0}};
  for (int k = 0; k < s.decomposition.num_imfs(); ++k)
    c.push_back({"imf" + std::to_string(k + 1), s.decomposition.imfs.col(k)});
  c.push_back({"residue", s.decomposition.residue});
  for (const auto& g : s.selection.groups)
    c.push_back({"group_" + std::string(sel::ToString(g.kind)), g.series});
  return io::RenderCsv(c);
}

std::string SelectionCsv(const StudyResult& s) {
  Table t;
  t.header = {"k",           "group",       "pdf_distance",   "self_distance",
              "noise_level", "log2_energy", "band_log2_upper"};
  auto at = [](const std::vector<double>& v, int k) {
    return k < static_cast<int>(v.size()) ? v[static_cast<size_t>(k)]
                                          : std::numeric_limits<double>::quiet_NaN();
  };
  for (int k = 0; k < s.decomposition.num_imfs(); ++k) {
    t.Add({std::to_string(k + 1), internal::GroupOf(s.selection, k + 1),
           at(s.selection.pdf_distance, k), at(s.selection.self_distance, k),
           at(s.selection.noise_level, k), at(s.selection.log2_energy, k),
           at(s.selection.energy_band_log2_upper, k)});
  }
  return t.Csv();
}

std::string PredictEstimatesCsv(const StudyResult& s) {
  const Eigen::Index split = s.predict.split_index;
  std::vector<io::CsvColumn> c{{"time_s", s.time_h.tail(s.output.size() - split) * 3600.0},
                               {s.simulated ? "drift_dph" : "reference", s.predict.reference}};
  for (const auto& r : s.predict.rows) {
    c.push_back(
        {std::string(drift::ToString(r.method)) + "_" + std::string(drift::ToString(r.protocol)),
         r.estimate});
  }
  return io::RenderCsv(c);
}

std::string CompensateEstimatesCsv(const StudyResult& s) {
  std::vector<io::CsvColumn> c{{"time_s", s.compensate_time_h * 3600.0},
                               {"output", s.compensate_output},
                               {s.simulated ? "drift_dph" : "reference", s.compensate_reference}};
  for (const auto& r : s.compensate) {
    c.push_back({std::string(drift::ToString(r.method)) + (s.simulated ? "" : "_" + r.protocol) +
                     "_estimate",
                 r.estimate});
  }
  return io::RenderCsv(c);
}

std::string AllanCsv(const StudyResult& s) {
  std::vector<io::CsvColumn> c;
  auto add = [&](const std::string& name, const allan::AllanResult& r) {
    if (r.points.empty()) return;
    Eigen::VectorXd dev(r.points.size()), lo(r.points.size()), hi(r.points.size());
    for (size_t i = 0; i < r.points.size(); ++i) {
      dev[i] = r.points[i].dev;
      lo[i] = r.points[i].dev_lo;
      hi[i] = r.points[i].dev_hi;
    }
    if (c.empty()) c.push_back({"tau_s", r.tau_s()});
    c.push_back({name + "_adev", dev});
    c.push_back({name + "_lo", lo});
    c.push_back({name + "_hi", hi});
  };
  add("raw", s.allan_raw);
  add("compensated", s.allan_compensated);
  if (!s.best_by.empty()) add("compensated_best", s.allan_best);
  if (s.simulated) add("noise_truth", s.allan_noise);
  return io::RenderCsv(c);
}

}  // namespace

std::vector<StudyFile> RenderStudyFiles(const StudyResult& s, const html::DygraphsAssets& assets) {
  std::vector<StudyFile> files;
  if (s.simulated) {
    files.push_back({"run_a.csv", SimulationCsv(s.run_a)});
    files.push_back({"run_b.csv", SimulationCsv(s.run_b)});
  }
  files.push_back({"imfs.csv", ImfsCsv(s)});
  files.push_back({"selection.csv", SelectionCsv(s)});
  files.push_back({"predict_table.csv", s.predict_table.Csv()});
  files.push_back({"compensate_table.csv", s.compensate_table.Csv()});
  files.push_back({"noise_terms.csv", s.terms_table.Csv()});
  files.push_back({"predict_estimates.csv", PredictEstimatesCsv(s)});
  files.push_back({"compensate_estimates.csv", CompensateEstimatesCsv(s)});
  files.push_back({"allan.csv", AllanCsv(s)});
  files.insert(files.end(), s.model_files.begin(), s.model_files.end());
  files.push_back({std::string(kStudyReportFile), RenderStudyReport(s, assets)});
  return files;
}

nlohmann::json StudyRecord(const StudyResult& s) {
  nlohmann::json record;
  record["drift_options"] = io::DriftOptionsToJson(s.drift_options);
  record["threads"] = s.threads;  // how it ran (0 = every core); no result depends on it
  record["decomposition"] = s.decomposition.report.Summary();
  record["selection"] = s.selection.Summary();
  record["stages_s"] = nlohmann::json::object();
  for (const auto& [name, sec] : s.stage_s) record["stages_s"][name] = sec;
  record["compensated_by"] = s.compensated_by;
  return record;
}

void RequireUsableOutputFolder(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path existing = fs::absolute(fs::path(folder), ec);
  if (ec) throw IoError(folder + ": not a usable output folder (" + ec.message() + ")");
  while (existing.has_relative_path() && !fs::exists(existing, ec)) {
    existing = existing.parent_path();
  }
  if (!fs::is_directory(existing, ec)) {
    throw IoError(folder + ": cannot create the output folder (" + existing.string() +
                  " is not a folder)");
  }
  if (::access(existing.c_str(), W_OK) != 0) {
    throw IoError(folder + ": cannot create the output folder (" + existing.string() + ": " +
                  std::strerror(errno) + ")");
  }
}

void WriteStudyFiles(const std::string& folder, const std::vector<StudyFile>& files,
                     const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  std::set<fs::path> folders{fs::path(folder)};
  std::vector<std::pair<std::string, std::string>> targets;
  for (const StudyFile& f : files) {
    const fs::path path = fs::path(folder) / f.name;
    folders.insert(path.parent_path());
    targets.push_back({path.string(), f.contents});
  }
  // The folders this call creates, parents first: a failed write removes them again (empty), so
  // that a refused or failed run leaves nothing behind, not even an empty models/.
  std::vector<fs::path> created;
  auto remove_created = [&created] {
    for (auto it = created.rbegin(); it != created.rend(); ++it) {
      std::error_code ignored;
      fs::remove(*it, ignored);  // only an empty folder goes
    }
  };
  for (const fs::path& dir : folders) {
    if (dir.empty()) continue;  // a file directly in the working folder
    std::vector<fs::path> missing;
    std::error_code ec;
    for (fs::path p = dir; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
      missing.push_back(p);
    }
    fs::create_directories(dir, ec);
    created.insert(created.end(), missing.rbegin(), missing.rend());
    if (ec) {
      remove_created();
      throw IoError(folder + ": cannot create the output folder (" + ec.message() + ")");
    }
  }
  try {
    io::WriteFilesAtomically(targets, inputs);
  } catch (...) {
    remove_created();
    throw;
  }
}

}  // namespace gyrodrift::study
