// The study's files: every CSV table and data file at full precision, the fitted compensation
// models, and one self-contained HTML report (html::HtmlReport, figures with captions saying what
// to look at), rendered from a StudyResult and written to a folder as one atomic set.
//
// Files (names relative to the output folder; docs/demo.md describes each):
//   run_a.csv, run_b.csv (simulation only), imfs.csv, selection.csv, predict_table.csv,
//   compensate_table.csv, predict_estimates.csv, compensate_estimates.csv, allan.csv,
//   noise_terms.csv, models/<method>_compensate.json, report.html.
// A caller adds its own record of how it was run (the demo's demo.json: StudyRecord plus its
// flags). Cost: O(samples x series); the report of the default demo is about 3 MB.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/html/report.h"
#include "gyrodrift/study/study.h"

namespace gyrodrift::study {

inline constexpr std::string_view kStudyReportFile = "report.html";

// The whole report: the data, the decomposition and grouping, both modes' tables and figures, the
// Allan deviations, the settings and the timing. `assets`: html::LoadDygraphs().
std::string RenderStudyReport(const StudyResult& result, const html::DygraphsAssets& assets);

// Every file listed above, the report last.
std::vector<StudyFile> RenderStudyFiles(const StudyResult& result,
                                        const html::DygraphsAssets& assets);

// What a record of the run needs beyond the caller's own options: drift_options, the
// decomposition and selection summaries, stages_s (wall seconds per stage) and compensated_by.
nlohmann::json StudyRecord(const StudyResult& result);

// Throws IoError unless `folder` exists as a writable folder or can be created (its nearest
// existing ancestor is a writable folder). For a check before the work, which takes half a minute
// or more, rather than when the files are written.
void RequireUsableOutputFolder(const std::string& folder);

// Creates `folder` and the subfolders the files name, then writes every file with
// io::WriteFilesAtomically: all are written or none is changed (and the folders it created are
// removed again). Throws IoError, and UsageError
// (no file written) when a file's path leads to one of `inputs` (a link left in the folder).
void WriteStudyFiles(const std::string& folder, const std::vector<StudyFile>& files,
                     const std::vector<std::string>& inputs = {});

}  // namespace gyrodrift::study
