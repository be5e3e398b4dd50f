// `fit_sim_model`: the adapter between a real log and sim::FitSimModel (libs/sim: the simulator's
// motor and firmware parameters fitted to the log with Ceres, its sensors' noise measured at the
// log's standstills). Writes sim_model_fit.json, sim_model.ini (the fitted keys, ready to paste into a
// simulator's [source]), sim_model_fit_series.csv and plots of the wheel speeds and the yaw rate.
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "mbot/common/atomic_file.hpp"
#include "mbot/common/config.hpp"
#include "mbot/common/log.hpp"
#include "mbot/drivers/plot.hpp"
#include "mbot/reports/json.hpp"
#include "mbot/sim/sim_model_fit.hpp"
#include "mbot/sim/sim_source_options.hpp"
#include "report.hpp"
#include "stages.hpp"

namespace mbot::app {
namespace {

using reports::Number;

reports::Json Part(const sim::SimFidelityResult& r) {
  return {{"wheel_speed_rmse_m_s", Number(r.wheel_speed_rmse_m_s)},
          {"wheel_speed_bias_m_s", Number(r.wheel_speed_bias_m_s)},
          {"yaw_rate_rmse_rad_s", Number(r.yaw_rate_rmse_rad_s)},
          {"path_drift_m_per_m", Number(r.path_drift_m_per_m)},
          {"heading_drift_deg_per_turn", Number(r.heading_drift_deg_per_turn)},
          {"path_final_error_m", Number(r.path_final_error_m)},
          {"odometry_drift_m_per_m", Number(r.odometry_drift_m_per_m)},
          {"true_path_m", Number(r.true_path_m)},
          {"duration_s", Number(r.duration_s)}};
}

class SimModelFitStage : public Stage {
 public:
  SimModelFitStage(sim::SimFidelityOptions base, sim::SimModelFitOptions fit) : base_(std::move(base)), fit_(fit) {}

  void OnEvent(const msgs::Event& ev) override { log_.push_back(ev); }

  void Finish(const RunContext& ctx, bool interrupted) override {
    const std::string dir = ctx.output_dir + "/";
    const sim::SensorNoiseEstimate noise = sim::EstimateSensorNoise(log_, base_, fit_.min_standstill_s);
    std::optional<sim::SimModelFitResult> fit;
    if (sim::WheelsTurned(log_)) {
      try {
        fit = sim::FitSimModel(log_, base_, fit_);
      } catch (const std::runtime_error& e) {
        // The sensors' noise is still written; the run fails after it, naming why.
        fit_error_ = e.what();
      }
    } else {
      mbot::log::Info("fit_sim_model: the robot stood still throughout: its sensors' noise only, no motor fit");
    }
    reports::Json j = {{"source", ctx.source_path}, {"interrupted", interrupted}};
    if (!fit_error_.empty()) j["fit_error"] = fit_error_;
    j["noise"] = {{"gyro_samples", noise.gyro_samples},
                  {"gyro_bias_rad_s", Number(noise.gyro_bias_rad_s)},
                  {"gyro_noise_rad_s", Number(noise.gyro_noise_rad_s)},
                  {"scans_at_standstill", noise.scans},
                  {"beams", noise.beams},
                  {"no_return_rate", Number(noise.no_return_rate)},
                  {"range_noise_m", Number(noise.range_noise_m)},
                  {"range_noise_by_range_m",
                   {{"under_1.5", Number(noise.range_noise_by_range_m[0])},
                    {"1.5_to_3", Number(noise.range_noise_by_range_m[1])},
                    {"3_to_4.5", Number(noise.range_noise_by_range_m[2])},
                    {"over_4.5", Number(noise.range_noise_by_range_m[3])}}}};
    std::string ini = "# fit_sim_model on " + ctx.source_path + "\n";
    if (std::isfinite(noise.gyro_noise_rad_s))
      ini += "gyro_noise_rad_s = " + Num(noise.gyro_noise_rad_s) +
             "\ngyro_bias_initial_rad_s = " + Num(std::abs(noise.gyro_bias_rad_s)) + "\n";
    if (std::isfinite(noise.range_noise_m)) ini += "lidar_range_noise_m = " + Num(noise.range_noise_m) + "\n";
    if (std::isfinite(noise.no_return_rate)) ini += "lidar_dropout = " + Num(noise.no_return_rate) + "\n";
    if (fit) {
      const sim::SimModelFitResult& f = *fit;
      reports::Json parameters = reports::Json::array();
      for (const sim::FittedParameter& p : f.parameters) {
        parameters.push_back(
            {{"key", p.key}, {"before", Number(p.before)}, {"after", Number(p.after)}, {"sigma", Number(p.sigma)}});
        ini += p.key + " = " + Num(p.after) + "\n";
      }
      j["fit"] = {{"split_s", Number(f.split_s)},
                  {"duration_s", Number(f.duration_s)},
                  {"windows", f.windows_fit},
                  {"iterations", f.iterations},
                  {"initial_cost", Number(f.initial_cost)},
                  {"final_cost", Number(f.final_cost)},
                  {"termination", f.termination},
                  {"parameters", parameters}};
      j["fitted_part"] = {{"before", Part(f.fit_before)}, {"after", Part(f.fit_after)}};
      j["held_out_part"] = {{"before", Part(f.held_before)}, {"after", Part(f.held_after)}};
      WriteSeries(f, dir);
      mbot::log::Info("fit_sim_model: " + f.termination + " after " + std::to_string(f.iterations) +
                      " iterations; held out from " + Num(f.split_s, 3) + " s: wheel speed RMSE " +
                      Num(f.held_before.wheel_speed_rmse_m_s, 3) + " -> " + Num(f.held_after.wheel_speed_rmse_m_s, 3) +
                      " m/s, path drift " + Num(f.held_before.path_drift_m_per_m, 3) + " -> " +
                      Num(f.held_after.path_drift_m_per_m, 3) + " m/m");
    }
    reports::WriteJson(dir + "sim_model_fit.json", j);
    WriteFileAtomically(dir + "sim_model.ini", [&](std::ostream& out) { out << ini; });
    mbot::log::Info("fit_sim_model: outputs in " + ctx.output_dir);
    if (!fit_error_.empty()) throw std::runtime_error(fit_error_ + " (the sensors' noise is written)");
  }

 private:
  // The wheels and the yaw rate over time: real, simulated before the fit and after it.
  static void WriteSeries(const sim::SimModelFitResult& f, const std::string& dir) {
    std::vector<sim::WheelWindow> before = f.fit_before.wheel_windows, after = f.fit_after.wheel_windows;
    before.insert(before.end(), f.held_before.wheel_windows.begin(), f.held_before.wheel_windows.end());
    after.insert(after.end(), f.held_after.wheel_windows.begin(), f.held_after.wheel_windows.end());
    WriteFileAtomically(dir + "sim_model_fit_series.csv", [&](std::ostream& out) {
      out << "t_s,part,real_left,real_right,before_left,before_right,after_left,after_right\n";
      for (size_t i = 0; i < before.size() && i < after.size(); ++i) {
        const sim::WheelWindow &b = before[i], &a = after[i];
        out << Num(b.t_s, 6) << "," << (b.t_s < f.split_s ? "fit" : "held_out") << "," << Num(b.real_left, 5) << ","
            << Num(b.real_right, 5) << "," << Num(b.sim_left, 5) << "," << Num(b.sim_right, 5) << ","
            << Num(a.sim_left, 5) << "," << Num(a.sim_right, 5) << "\n";
      }
    });
    drivers::PlotSeries real{{}, {}, 0, 0, 0, false, "real (encoders)"};
    drivers::PlotSeries b{{}, {}, 220, 0, 0, false, "simulated, before the fit"};
    drivers::PlotSeries a{{}, {}, 0, 60, 255, false, "simulated, fitted model"};
    for (size_t i = 0; i < before.size() && i < after.size(); ++i) {
      real.x.push_back(before[i].t_s), real.y.push_back(before[i].real_left);
      b.x.push_back(before[i].t_s), b.y.push_back(before[i].sim_left);
      a.x.push_back(after[i].t_s), a.y.push_back(after[i].sim_left);
    }
    drivers::PlotSeries split{{f.split_s, f.split_s}, {-0.5, 0.5}, 0, 170, 0, false, "fit | held out"};
    drivers::WritePlotPng({real, b, a, split}, {"left wheel speed over 0.2 s windows", "time [s]", "speed [m/s]"},
                          dir + "sim_model_fit_wheels.png");
    drivers::PlotSeries yr{{}, {}, 0, 0, 0, false, "real (gyro)"};
    drivers::PlotSeries yb{{}, {}, 220, 0, 0, false, "simulated, before the fit"};
    drivers::PlotSeries ya{{}, {}, 0, 60, 255, false, "simulated, fitted model"};
    for (const auto* part : {&f.fit_before, &f.held_before})
      for (const sim::YawWindow& w : part->yaw_windows) yr.x.push_back(w.t_s), yr.y.push_back(w.real);
    for (const auto* part : {&f.fit_before, &f.held_before})
      for (const sim::YawWindow& w : part->yaw_windows) yb.x.push_back(w.t_s), yb.y.push_back(w.sim);
    for (const auto* part : {&f.fit_after, &f.held_after})
      for (const sim::YawWindow& w : part->yaw_windows) ya.x.push_back(w.t_s), ya.y.push_back(w.sim);
    split.y = {-3.0, 3.0};
    drivers::WritePlotPng({yr, yb, ya, split}, {"yaw rate over 0.2 s windows", "time [s]", "rate [rad/s]"},
                          dir + "sim_model_fit_yaw.png");
  }

  sim::SimFidelityOptions base_;
  sim::SimModelFitOptions fit_;
  std::vector<msgs::Event> log_;
  std::string fit_error_;
};

}  // namespace

const RegisterStage kSimModelFitRegistered{
    {"fit_sim_model",
     "fits the simulator's motor and firmware parameters to a real log's wheel speeds and yaw rate (Ceres, robust "
     "loss, part of the log held out) and measures its sensors' noise at standstill (sim_model_fit.json, "
     "sim_model.ini)",
     [](config::Section& s) -> std::unique_ptr<Stage> {
       sim::SimFidelityOptions base = sim::ParseSimFidelityOptions(s);
       sim::SimModelFitOptions f;
       f.split_s = s.GetDouble("split_s", f.split_s,
                               "fit on the log before this [s from its first motion-capture pose], hold out the rest; "
                               "unset: when the wheels have turned half their rotation",
                               0.0, 1e9);
       f.min_standstill_s = s.GetDouble("min_standstill_s", f.min_standstill_s,
                                        "a standstill: the encoders count nothing for this long [s]", 0.05, 100.0);
       f.huber_m_s =
           s.GetDouble("huber_m_s", f.huber_m_s, "the Huber loss's scale on speed residuals [m/s]", 1e-4, 10.0);
       f.max_iterations = static_cast<int>(
           s.GetInt("max_iterations", f.max_iterations, "Levenberg-Marquardt iterations at most", 1, 1000));
       return std::make_unique<SimModelFitStage>(std::move(base), f);
     }}};

}  // namespace mbot::app
