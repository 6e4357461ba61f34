// Every sentence rbsim check's report prints, in one file (report.cpp, beside format_report): the
// comparer (check.cpp, compare_values.cpp) keeps plain data and asks here for its text.
#pragma once

#include <cstdint>
#include <string>

#include "rbsim/check.hpp"
#include "rbsim/msgs.hpp"
#include "steps.hpp"

namespace rbsim::check {

// Numbers and values.
std::string ordinal(std::uint64_t n);           // "2nd", "10th"
std::string fmt_short(double v);                // "%.6g"
std::string value_text(const msgs::Scalar& s);  // floats in shortest round-trip form
const char* to_string(msgs::Scalar::Kind k);    // FieldStats::kind: "float", "length", ...
std::string quoted(const std::string& s);       // "'chain'", or "(none)" for ""

// Steps in one file only: "0..999", "5, 15, ..., 995", "0, 10, 20 and more".
std::string step_runs_text(const StepRuns& runs);
// "run lacks steps 0..999 (1,000 messages: recorder joined late?)": the steps of a topic only in
// the golden (golden_only) or only in the run, with a likely cause from both files' tracks.
std::string only_summary(const StepRuns& runs, bool golden_only, const StepTrack& run,
                         const StepTrack& golden);

// Why two scene descriptions are not the same scene, or "" when they are: a different structure
// (bodies, hull vertex counts, which bodies each spring joins, force fields, integrator). Values
// (masses, vertex positions, stiffnesses, dt) are left to the field comparison and its tolerance:
// a perturbed run of the same scene is compared value by value.
std::string scene_difference(const msgs::SceneMessage& golden, const msgs::SceneMessage& run);
// CheckReport::scene_mismatch: the two scenes' names and scene_difference()'s `why`.
std::string different_scenes(const msgs::SceneMessage& golden, const msgs::SceneMessage& run,
                             const std::string& why);

// Topic-level differences (CheckReport::topic_problems, after "<topic>: ").
std::string topic_only_in(const std::string& role, std::uint64_t messages);  // role: "run", "golden"
std::string schema_differs(const std::string& golden, const std::string& run);
std::string encoding_differs(const std::string& golden_message, const std::string& golden_schema,
                             const std::string& run_message, const std::string& run_schema);
std::string fields_differ(const std::string& schema);

// A per-step message in one file only: "message missing from the run" (golden_only) or "extra
// message in the run".
std::string message_in_one_file(bool golden_only);
// Messages left over at the end of a topic: "message missing from the run: the golden has 10
// messages on this topic, the run 9" (golden_only) or "extra message in the run: ...".
std::string messages_left_over(bool golden_only, std::uint64_t run_messages, std::uint64_t golden_messages);

// First differences that are not one value's.
FirstDifference topic_difference(const std::string& topic, const std::string& what);  // topic "": file
FirstDifference message_difference(const std::string& topic, bool has_step, std::uint64_t step,
                                   const std::string& what);
void add_detail(FirstDifference& d, const std::string& detail);  // "(what)" -> "(what: detail)"
FirstDifference bytes_difference(const std::string& topic, std::uint64_t index, std::size_t golden_bytes,
                                 std::size_t run_bytes);
FirstDifference log_time_difference(const std::string& topic, bool has_step, std::uint64_t step,
                                    std::uint64_t golden_ns, std::uint64_t run_ns);

// Metadata differences.
MetadataDifference header_difference(const std::string& what, const std::string& golden,
                                     const std::string& run);
MetadataDifference metadata_difference(const std::string& topic, const std::string& path,
                                       const msgs::Scalar& golden, const msgs::Scalar& run);

}  // namespace rbsim::check
