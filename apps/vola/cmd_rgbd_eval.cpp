// vola rgbd-eval: absolute trajectory error and relative pose error of an estimated
// trajectory against ground truth, as TUM RGB-D's evaluate_ate.py / evaluate_rpe.py.
#include <cstdio>
#include <memory>
#include <string>

#include "commands.hpp"
#include "number_checks.hpp"
#include "vola/slam/trajectory_error.hpp"

namespace vola::cli {

namespace {

struct EvalArgs {
  std::string groundtruth, estimate;
  double max_difference = 0.02;
  std::size_t delta = 1;
  bool numbered = false;
};

void run_eval(const EvalArgs& a) {
  const auto truth = a.numbered ? slam::read_numbered_poses(a.groundtruth) : slam::read_trajectory(a.groundtruth);
  const auto estimate = slam::read_trajectory(a.estimate);
  const auto ate = slam::absolute_trajectory_error(truth, estimate, a.max_difference);
  std::printf("ate_pairs %zu\nate_rmse_m %.6f\nate_mean_m %.6f\nate_median_m %.6f\nate_max_m %.6f\n", ate.pairs, ate.rmse,
              ate.mean, ate.median, ate.max);
  const auto rpe = slam::relative_pose_error(truth, estimate, a.delta, a.max_difference);
  std::printf("rpe_pairs %zu\nrpe_translation_rmse_m %.6f\nrpe_translation_mean_m %.6f\n"
              "rpe_rotation_rmse_deg %.6f\nrpe_rotation_mean_deg %.6f\n",
              rpe.pairs, rpe.translation_rmse, rpe.translation_mean, rpe.rotation_rmse_degrees, rpe.rotation_mean_degrees);
}

}  // namespace

void add_rgbd_eval(CLI::App& app) {
  auto a = std::make_shared<EvalArgs>();
  auto* cmd = app.add_subcommand("rgbd-eval", "Trajectory errors (ATE, RPE) of an estimate against ground truth");
  cmd->footer(
      "Both files are \"timestamp tx ty tz qx qy qz qw\" (TUM format); poses are associated by nearest\n"
      "timestamp within --max-difference seconds. ATE: RMSE of position differences after the rigid\n"
      "(rotation + translation) least-squares alignment of the estimate onto the ground truth (Horn).\n"
      "RPE: over pose pairs --delta frames apart, the error of the estimated relative motion.\n"
      "Example:\n"
      "  vola rgbd-eval room/groundtruth.txt est.txt\n"
      "  vola rgbd-eval frames/pose.txt est.txt --numbered    # 'tx ty tz qx qy qz qw' lines for frames 1, 2, ...");
  cmd->add_option("groundtruth", a->groundtruth, "Ground-truth trajectory")->required()->check(CLI::ExistingFile);
  cmd->add_option("estimate", a->estimate, "Estimated trajectory")->required()->check(CLI::ExistingFile);
  cmd->add_option("--max-difference", a->max_difference, "Timestamp association window (s)")->check(non_negative_number());
  cmd->add_option("--delta", a->delta, "RPE frame distance")->check(positive_number());
  cmd->add_flag("--numbered", a->numbered, "Ground truth has no timestamps: line i is frame i (timestamp i)");
  cmd->callback([a] { run_eval(*a); });
}

}  // namespace vola::cli
