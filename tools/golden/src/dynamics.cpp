// The stages on the dynamics (stages.hpp): the recorded states re-integrated with the verifier's
// own integrator, then against an independent result: the FOSSSim reference's output, or the
// energy conservation of symplectic Euler.
#include <algorithm>
#include <cmath>

#include "rbsim/fosssim.hpp"
#include "stages.hpp"

namespace rbsim::check {

namespace {

// The golden's body states against the reference's free run, and the recorded quantities (M, I
// from the scene description, P, L, T, U from the energy terms) against the reference's.
void compare_with_reference(const StageContext& c, const FosssimLog& reference, const RecordedRun& run,
                            const msgs::SceneMessage& desc,
                            const std::vector<msgs::EnergyTermsMessage>& energy, Tally& states,
                            Tally& quantities) {
  const std::size_t bodies = c.model.mass.size();
  const double state_tol = c.options.state_tol, quantity_tol = c.options.quantity_tol;
  for (std::size_t b = 0; b < bodies; ++b) {
    const std::string id = "body " + std::to_string(b);
    quantities.add(desc.bodies[b].mass, reference.mass[b], quantity_tol, [&] { return id + " M"; });
    quantities.add(desc.bodies[b].inertia, reference.inertia[b], quantity_tol, [&] { return id + " I"; });
  }
  for (std::size_t m = 0; m < run.states.size(); ++m) {
    const std::uint64_t step = run.steps[m];
    if (step >= reference.frames.size()) {
      states.fail("step " + std::to_string(step) + " is past the reference's " +
                  std::to_string(reference.frames.size() - 1));
      break;
    }
    const FosssimFrame& f = reference.frames[step];
    const State& s = run.states[m];
    const std::string at = "step " + std::to_string(step) + " body ";
    for (std::size_t b = 0; b < bodies; ++b) {
      const BodyState& want = f.states[b];
      auto where = [&](const char* what) {
        return [&, what] { return at + std::to_string(b) + " " + what; };
      };
      states.add(s.x[b], want.position.x(), state_tol, where("x"));
      states.add(s.y[b], want.position.y(), state_tol, where("y"));
      states.add(s.theta[b], want.theta, state_tol, where("theta"));
      states.add(s.vx[b], want.velocity.x(), state_tol, where("vx"));
      states.add(s.vy[b], want.velocity.y(), state_tol, where("vy"));
      states.add(s.omega[b], want.omega, state_tol, where("omega"));
      const BodyQuantities& wq = f.quantities[b];
      const msgs::EnergyTermsMessage::Body& eb = energy[m].bodies[b];
      quantities.add(eb.momentum.x(), wq.momentum.x(), quantity_tol, where("P.x"));
      quantities.add(eb.momentum.y(), wq.momentum.y(), quantity_tol, where("P.y"));
      quantities.add(eb.l_point, wq.l_point, quantity_tol, where("L_point"));
      quantities.add(eb.l_spin, wq.l_spin, quantity_tol, where("L_spin"));
      quantities.add(eb.t_point, wq.t_point, quantity_tol, where("T_point"));
      quantities.add(eb.t_spin, wq.t_spin, quantity_tol, where("T_spin"));
    }
    quantities.add(energy[m].potential, f.potential, quantity_tol,
                   [&] { return "step " + std::to_string(step) + " U"; });
  }
}

}  // namespace

void verify_integration(const StageContext& c, const RecordedRun& run) {
  Tally tally;
  const double tol = c.options.integration_tol;
  const std::size_t bodies = c.model.mass.size();
  for (std::size_t m = 0; m + 1 < run.states.size(); ++m) {
    State s = run.states[m];
    for (std::uint64_t k = run.steps[m]; k < run.steps[m + 1]; ++k) step_state(c.model, c.scene, s);
    const State& want = run.states[m + 1];
    for (std::size_t b = 0; b < bodies; ++b) {
      const std::string at = "step " + std::to_string(run.steps[m + 1]) + " body " + std::to_string(b);
      // The recorded value is the one compared: the integrated one is the expectation.
      auto add = [&](double integrated, double recorded, const char* what) {
        tally.add(recorded, integrated, tol * std::max(1.0, std::fabs(integrated)),
                  [&] { return at + " " + what; });
      };
      add(s.x[b], want.x[b], "x");
      add(s.y[b], want.y[b], "y");
      add(s.theta[b], want.theta[b], "theta");
      add(s.vx[b], want.vx[b], "vx");
      add(s.vy[b], want.vy[b], "vy");
      add(s.omega[b], want.omega[b], "omega");
    }
  }
  GoldenVerification& v = c.verification();
  c.report.line(tally.ok(),
                "independent integration: from each recorded state, " + std::to_string(v.record_every) +
                    " steps of the verifier's own " + to_string(c.scene.world.integrator) +
                    " (gravity, springs, wind summed over its sample points) reach the next recorded "
                    "state (tolerance " +
                    three_digits(tol) + " x max(1, |value|)): " + tally.summary());
  if (tally.ok()) v.rule = "independent-integration";
}

Status verify_reference(const StageContext& c, const FosssimMatch& match, const RecordedRun& run,
                        const msgs::SceneMessage& desc, const std::vector<msgs::EnergyTermsMessage>& energy) {
  GoldenVerification& v = c.verification();
  v.rule = "fosssim-reference, " + v.rule;
  c.report.info("the scene is FOSSSim's " + match.scene + ", reference output " + match.reference);
  Result<std::vector<std::byte>> bytes = read_file(match.reference);
  if (!bytes) return bytes.error();
  Result<FosssimLog> reference = parse_fosssim(bytes.value(), static_cast<std::int32_t>(c.model.mass.size()));
  if (!reference) return with_context(match.reference + ": ", reference.error());
  Result<GradeReport> graded = grade(c.scene, reference.value());
  if (!graded) return graded.error();
  const GradeReport& gr = graded.value();
  c.report.line(gr.passed, "grade (the reference's rule, as rbsim grade): " + std::to_string(gr.steps) +
                               " steps, max step diff " + three_digits(gr.max_step_diff) + ", summed " +
                               three_digits(gr.sum_step_diff) + ", max quantity diff " +
                               three_digits(gr.max_quantity_diff) + (gr.passed ? "" : ": " + gr.message));
  Tally states, quantities;
  compare_with_reference(c, reference.value(), run, desc, energy, states, quantities);
  c.report.line(states.ok(), "body states of the " + std::to_string(run.states.size()) +
                                 " recorded steps against the reference's free run (absolute tolerance " +
                                 three_digits(c.options.state_tol) + "): " + states.summary());
  c.report.line(quantities.ok(),
                "M, I, P, L_point, L_spin, T_point, T_spin, U of the recorded steps against the reference's "
                "(absolute tolerance " +
                    three_digits(c.options.quantity_tol) + "): " + quantities.summary());
  return Ok{};
}

void verify_energy_conservation(const StageContext& c, const RecordedRun& run) {
  GoldenVerification& v = c.verification();
  v.rule = "symplectic-energy, " + v.rule;
  // Symplectic Euler on H = T(P, L) + U(X, theta) (separable: I is constant in 2D) conserves the
  // modified energy E + (dt / 2) Pi up to O(dt^2), Pi being the power of the conservative forces.
  const std::vector<Terms>& terms = run.terms;
  const double dt = c.scene.world.dt;
  double max_power = 0.0, max_scale = 0.0, err = 0.0, modified = 0.0;
  std::uint64_t worst = 0;
  for (const Terms& t : terms) {
    max_power = std::max(max_power, std::fabs(t.power));
    max_scale = std::max(max_scale, t.scale);
  }
  const double e0 = terms.front().total, m0 = e0 + 0.5 * dt * terms.front().power;
  for (std::size_t m = 0; m < terms.size(); ++m) {
    const double d = std::fabs(terms[m].total - e0);
    if (d > err || std::isnan(d)) {
      err = std::isnan(d) ? HUGE_VAL : d;
      worst = run.steps[m];
    }
    modified = std::max(modified, std::fabs(terms[m].total + 0.5 * dt * terms[m].power - m0));
  }
  // First order: |E_n - E_0| ~ (dt/2) |Pi_n - Pi_0| <= (dt/2) (max|Pi| + |Pi_0|); the bound is twice
  // that (room for the O(dt^2) remainder), plus rounding.
  const double bound = dt * (max_power + std::fabs(terms.front().power)) + 1e-12 * max_scale;
  v.energy_error = err;
  v.energy_bound = bound;
  c.report.line(err <= bound,
                "energy conservation (symplectic Euler, gravity and springs): E = T + U recomputed from the "
                "recorded states; max |E - E0| = " +
                    three_digits(err) + " at step " + std::to_string(worst) +
                    " <= dt * (max|Pi| + |Pi_0|) + 1e-12 * max(sum |terms|) = " + three_digits(bound) +
                    " (ratio " + three_digits(bound > 0 ? err / bound : 0.0) +
                    ", E0 = " + full_precision(e0) + ", max|Pi| = " + three_digits(max_power) + ")");
  c.report.info("modified energy E + dt/2 Pi drifts by at most " + three_digits(modified) +
                " (first-order backward error analysis)");
}

}  // namespace rbsim::check
