// The study's files (src/study/study_files.cc; named study_files_test, not files_test, because test
// targets are unit_<stem> and tests/unit/io/files_test.cc holds that name). From one small log
// study: every CSV carries its result's numbers exactly (read back to the same doubles) under
// the documented column names, in the order of the results; the record holds the run's stages;
// the set is written into its subfolders all at once or not at all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/study/study_files.h"
#include "gyrodrift/study/study.h"
#include "unit/study/chamber_log.h"
#include "study/study_steps.h"  // GroupOf, private to src/study
#include "support/test_support.h"

namespace gyrodrift::study {
namespace {

namespace fs = std::filesystem;

// A 40-minute chamber log studied with the cheapest settings that run every step: poly only
// (no causal decompositions), a 4-member ensemble.
const StudyResult& LogStudy() {
  static const StudyResult* const result = [] {
    StudyOptions o;
    o.ensemble_size = 4;
    o.causal.window = 32;
    o.methods = {drift::Method::kPoly};
    return new StudyResult(RunStudy(o, ChamberLog(), {.threads = 2}));
  }();
  return *result;
}

std::map<std::string, std::string> ByName(const std::vector<StudyFile>& files) {
  std::map<std::string, std::string> out;
  for (const StudyFile& f : files) out[f.name] = f.contents;
  return out;
}

// A rendered CSV as text cells (the study writes no quoted cells). Compared as text rather than
// through io::CsvTable, which refuses the NaN cells some columns legitimately hold.
struct CsvCells {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  explicit CsvCells(const std::string& text) {
    std::vector<std::vector<std::string>> lines;
    for (size_t p = 0, q; (q = text.find('\n', p)) != std::string::npos; p = q + 1) {
      const std::string line = text.substr(p, q - p);
      std::vector<std::string> cells;
      for (size_t a = 0, b;; a = b + 1) {
        b = line.find(',', a);
        cells.push_back(line.substr(a, b == std::string::npos ? b : b - a));
        if (b == std::string::npos) break;
      }
      lines.push_back(std::move(cells));
    }
    if (lines.empty()) return;
    header = lines.front();
    rows.assign(lines.begin() + 1, lines.end());
  }
  // The cells of column `name`.
  std::vector<std::string> Column(const std::string& name) const {
    const auto c =
        static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin());
    std::vector<std::string> out;
    if (c == header.size()) {
      ADD_FAILURE() << "no column " << name;
      return out;
    }
    for (const auto& row : rows) out.push_back(c < row.size() ? row[c] : "<missing>");
    return out;
  }
};

// The cells that hold `values` exactly (the shortest text that reads back to each double).
std::vector<std::string> Exactly(const Eigen::Ref<const Eigen::VectorXd>& values) {
  std::vector<std::string> out;
  for (Eigen::Index i = 0; i < values.size(); ++i) out.push_back(io::FormatDouble(values[i]));
  return out;
}

TEST(RenderStudyFiles, ALogStudyHasEveryFileButTheRunsAndTheReportLast) {
  const StudyResult& s = LogStudy();
  const std::vector<StudyFile> files = RenderStudyFiles(s, test::FakeDygraphs());
  std::vector<std::string> names;
  for (const StudyFile& f : files) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{
                       "imfs.csv", "selection.csv", "predict_table.csv", "compensate_table.csv",
                       "noise_terms.csv", "predict_estimates.csv", "compensate_estimates.csv",
                       "allan.csv", "models/poly_compensate.json", "report.html"}));
  // The tables' CSV files are the tables' own full-precision renderings.
  const auto by_name = ByName(files);
  EXPECT_EQ(by_name.at("predict_table.csv"), s.predict_table.Csv());
  EXPECT_EQ(by_name.at("compensate_table.csv"), s.compensate_table.Csv());
  EXPECT_EQ(by_name.at("noise_terms.csv"), s.terms_table.Csv());
  EXPECT_EQ(by_name.at("models/poly_compensate.json"), s.model_files.at(0).contents);
  EXPECT_EQ(by_name.at("report.html"), RenderStudyReport(s, test::FakeDygraphs()));
}

TEST(RenderStudyFiles, ImfsCsvHoldsTheDecompositionAndTheGroupsExactly) {
  const StudyResult& s = LogStudy();
  const CsvCells t(ByName(RenderStudyFiles(s, test::FakeDygraphs())).at("imfs.csv"));
  const int k = s.decomposition.num_imfs();
  ASSERT_GE(k, 2);
  std::vector<std::string> header = {"time_s"};
  for (int i = 1; i <= k; ++i) header.push_back("imf" + std::to_string(i));
  header.push_back("residue");
  for (const auto& g : s.selection.groups) {
    header.push_back("group_" + std::string(selection::ToString(g.kind)));
  }
  EXPECT_EQ(t.header, header);
  EXPECT_EQ(t.Column("time_s"), Exactly(s.time_h * 3600.0));
  for (int i = 0; i < k; ++i) {
    EXPECT_EQ(t.Column("imf" + std::to_string(i + 1)), Exactly(s.decomposition.imfs.col(i)));
  }
  EXPECT_EQ(t.Column("residue"), Exactly(s.decomposition.residue));
  for (const auto& g : s.selection.groups) {
    EXPECT_EQ(t.Column("group_" + std::string(selection::ToString(g.kind))), Exactly(g.series));
  }
}

TEST(RenderStudyFiles, SelectionCsvHasOneRowPerImfWithItsGroupAndCurves) {
  const StudyResult& s = LogStudy();
  const CsvCells t(ByName(RenderStudyFiles(s, test::FakeDygraphs())).at("selection.csv"));
  const int k = s.decomposition.num_imfs();
  EXPECT_EQ(t.header, (std::vector<std::string>{"k", "group", "pdf_distance", "self_distance",
                                                "noise_level", "log2_energy", "band_log2_upper"}));
  ASSERT_EQ(static_cast<int>(t.rows.size()), k);
  // A curve shorter than the IMFs is padded with NaN, never read past its end.
  const auto curve = [k](const std::vector<double>& v) {
    Eigen::VectorXd out = Eigen::VectorXd::Constant(k, std::nan(""));
    for (int i = 0; i < k && i < static_cast<int>(v.size()); ++i)
      out[i] = v[static_cast<size_t>(i)];
    return out;
  };
  std::vector<std::string> ks, groups;
  for (int i = 1; i <= k; ++i) {
    ks.push_back(std::to_string(i));
    groups.push_back(internal::GroupOf(s.selection, i));
  }
  EXPECT_EQ(t.Column("k"), ks);
  EXPECT_EQ(t.Column("group"), groups);
  EXPECT_EQ(t.Column("pdf_distance"), Exactly(curve(s.selection.pdf_distance)));
  EXPECT_EQ(t.Column("self_distance"), Exactly(curve(s.selection.self_distance)));
  EXPECT_EQ(t.Column("noise_level"), Exactly(curve(s.selection.noise_level)));
  EXPECT_EQ(t.Column("log2_energy"), Exactly(curve(s.selection.log2_energy)));
  EXPECT_EQ(t.Column("band_log2_upper"), Exactly(curve(s.selection.energy_band_log2_upper)));
}

TEST(RenderStudyFiles, EstimatesCsvsHoldEveryRowsEstimateOnItsTimeAxis) {
  const StudyResult& s = LogStudy();
  const auto files = ByName(RenderStudyFiles(s, test::FakeDygraphs()));
  // Predict mode: the test block's times, the measured output (a log has no truth), one column
  // per method and protocol.
  const CsvCells p(files.at("predict_estimates.csv"));
  std::vector<std::string> header = {"time_s", "reference"};
  for (const auto& r : s.predict.rows) {
    header.push_back(std::string(drift::ToString(r.method)) + "_" +
                     std::string(drift::ToString(r.protocol)));
  }
  EXPECT_EQ(p.header, header);
  const Eigen::Index split = s.predict.split_index;
  ASSERT_GT(split, 0);
  ASSERT_FALSE(s.predict.rows.empty());
  EXPECT_EQ(p.Column("time_s"), Exactly(s.time_h.tail(s.output.size() - split) * 3600.0));
  EXPECT_EQ(p.Column("reference"), Exactly(s.predict.reference));
  for (size_t i = 0; i < s.predict.rows.size(); ++i) {
    EXPECT_EQ(p.Column(header[i + 2]), Exactly(s.predict.rows[i].estimate)) << header[i + 2];
  }
  // Compensate mode: the raw output beside the reference, a log's rows named with their protocol.
  const CsvCells c(files.at("compensate_estimates.csv"));
  header = {"time_s", "output", "reference"};
  for (const auto& r : s.compensate) {
    header.push_back(std::string(drift::ToString(r.method)) + "_" + r.protocol + "_estimate");
  }
  EXPECT_EQ(c.header, header);
  ASSERT_FALSE(s.compensate.empty());
  EXPECT_EQ(c.Column("time_s"), Exactly(s.compensate_time_h * 3600.0));
  EXPECT_EQ(c.Column("output"), Exactly(s.compensate_output));
  EXPECT_EQ(c.Column("reference"), Exactly(s.compensate_reference));
  for (size_t i = 0; i < s.compensate.size(); ++i) {
    EXPECT_EQ(c.Column(header[i + 3]), Exactly(s.compensate[i].estimate)) << header[i + 3];
  }
}

TEST(RenderStudyFiles, AllanCsvHoldsEachCurveWithItsBands) {
  const StudyResult& s = LogStudy();
  const CsvCells t(ByName(RenderStudyFiles(s, test::FakeDygraphs())).at("allan.csv"));
  std::vector<std::pair<std::string, const allan::AllanResult*>> curves = {
      {"raw", &s.allan_raw}, {"compensated", &s.allan_compensated}};
  // The best method's curve only when one is clearly better; no noise truth for a log.
  if (!s.best_by.empty()) curves.push_back({"compensated_best", &s.allan_best});
  std::vector<std::string> header = {"tau_s"};
  for (const auto& [name, r] : curves) {
    for (const char* part : {"_adev", "_lo", "_hi"}) header.push_back(name + part);
  }
  EXPECT_EQ(t.header, header);
  EXPECT_EQ(t.Column("tau_s"), Exactly(s.allan_raw.tau_s()));
  for (const auto& [name, r] : curves) {
    Eigen::VectorXd dev(r->points.size()), lo(r->points.size()), hi(r->points.size());
    for (size_t i = 0; i < r->points.size(); ++i) {
      dev[static_cast<Eigen::Index>(i)] = r->points[i].dev;
      lo[static_cast<Eigen::Index>(i)] = r->points[i].dev_lo;
      hi[static_cast<Eigen::Index>(i)] = r->points[i].dev_hi;
    }
    EXPECT_EQ(t.Column(name + "_adev"), Exactly(dev)) << name;
    EXPECT_EQ(t.Column(name + "_lo"), Exactly(lo)) << name;
    EXPECT_EQ(t.Column(name + "_hi"), Exactly(hi)) << name;
  }
}

TEST(StudyRecord, HoldsTheRunsStagesInOrderAndItsSummaries) {
  const StudyResult& s = LogStudy();
  const nlohmann::json record = StudyRecord(s);
  EXPECT_EQ(record["threads"], 2);
  EXPECT_EQ(record["compensated_by"], s.compensated_by);
  EXPECT_EQ(record["decomposition"], s.decomposition.report.Summary());
  EXPECT_EQ(record["selection"], s.selection.Summary());
  ASSERT_EQ(record["stages_s"].size(), s.stage_s.size());
  for (const auto& [name, seconds] : s.stage_s)
    EXPECT_EQ(record["stages_s"][name], seconds) << name;
  EXPECT_TRUE(record["drift_options"].is_object());
}

TEST(WriteStudyFiles, WritesTheSetWithItsSubfolders) {
  const std::string dir = test::TempDir("study_files") + "/out/deeper";
  EXPECT_NO_THROW(RequireUsableOutputFolder(dir));
  WriteStudyFiles(dir, {{"a.csv", "x\n1\n"}, {"models/m.json", "{}\n"}});
  EXPECT_EQ(io::ReadTextFile(dir + "/a.csv"), "x\n1\n");
  EXPECT_EQ(io::ReadTextFile(dir + "/models/m.json"), "{}\n");
  // A file where a folder should be: refused up front, and by the writer.
  EXPECT_THROW(RequireUsableOutputFolder(dir + "/a.csv/sub"), IoError);
  EXPECT_THROW(WriteStudyFiles(dir + "/a.csv/sub", {{"b.csv", "y\n"}}), IoError);
}

// A link in the folder that leads to the study's input log is refused before anything is written.
TEST(WriteStudyFiles, NeverWritesThroughALinkToAnInput) {
  const std::string dir = test::TempDir("study_files_link");
  io::WriteFileAtomically(dir + "/log.csv", "x\n1\n");
  fs::create_directories(dir + "/out");
  fs::create_symlink(fs::absolute(dir + "/log.csv"), dir + "/out/imfs.csv");
  EXPECT_THROW(
      WriteStudyFiles(dir + "/out", {{"a.csv", "y\n"}, {"imfs.csv", "z\n"}}, {dir + "/log.csv"}),
      UsageError);
  EXPECT_EQ(io::ReadTextFile(dir + "/log.csv"), "x\n1\n");
  EXPECT_FALSE(fs::exists(dir + "/out/a.csv"));
  // Nor does the refused set leave the subfolders it made (the folder that was there stays).
  EXPECT_THROW(WriteStudyFiles(dir + "/out", {{"models/deep/m.json", "{}\n"}, {"imfs.csv", "z\n"}},
                               {dir + "/log.csv"}),
               UsageError);
  EXPECT_FALSE(fs::exists(dir + "/out/models"));
  EXPECT_TRUE(fs::exists(dir + "/out/imfs.csv"));
}

TEST(WriteStudyFiles, AFailingFileChangesNoneOfTheSet) {
  const std::string dir = test::TempDir("study_files_set");
  WriteStudyFiles(dir, {{"a.csv", "old\n"}, {"models/m.json", "{}\n"}});
  // report.html is a folder: the set is refused and a.csv and the model keep their contents.
  fs::create_directories(dir + "/report.html");
  EXPECT_THROW(WriteStudyFiles(dir, {{"a.csv", "new\n"},
                                     {"models/m.json", "{\"new\": 1}\n"},
                                     {"report.html", "<html>"}}),
               IoError);
  EXPECT_EQ(io::ReadTextFile(dir + "/a.csv"), "old\n");
  EXPECT_EQ(io::ReadTextFile(dir + "/models/m.json"), "{}\n");
  std::vector<std::string> entries;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    entries.push_back(fs::relative(e.path(), dir).string());
  }
  std::sort(entries.begin(), entries.end());
  EXPECT_EQ(entries, (std::vector<std::string>{"a.csv", "models", "models/m.json", "report.html"}));
}

TEST(RequireUsableOutputFolder, AcceptsAFolderToBeMadeAndRefusesAFileInTheWay) {
  const std::string dir = test::TempDir("study_usable");
  EXPECT_NO_THROW(RequireUsableOutputFolder(dir));
  EXPECT_NO_THROW(RequireUsableOutputFolder(dir + "/not/yet/there"));
  EXPECT_FALSE(fs::exists(dir + "/not"));  // a check, not a creation
  io::WriteFileAtomically(dir + "/file", "x");
  try {
    RequireUsableOutputFolder(dir + "/file/sub");
    FAIL() << "nothing thrown";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/file/sub: cannot create the output folder (" + dir +
                                         "/file is not a folder)");
  }
  EXPECT_THROW(RequireUsableOutputFolder(dir + "/file"), IoError);
}

}  // namespace
}  // namespace gyrodrift::study
