// `nipdem rc response` (forward model of the probe circuit, thesis eqs. 4.7.1–4.7.7) and
// `nipdem calibrate rc` (least-squares fit of R, Rd, C to measured amplitude/phase).
#include <cmath>
#include <fmt/format.h>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "nipdem/experiments/calibrate_rc.hpp"
#include "nipdem/io/print_pattern.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/models/rc_charge.hpp"
#include "nipdem/models/probe_circuit.hpp"
#include "registry.hpp"

namespace {

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// --voltage of rc response and calibrate rc (experiments/calibrate_rc.hpp).
using nipdem::probe::check_amplitude;

struct ResponseOpts {
  nipdem::probe::ProbeCircuitParams p;
  double voltage = 40.0;
  std::string freq;
  bool json = false;
};

struct ChargeOpts {
  std::string pattern;
  double R = 5.9e11, Rd = 1.8e24, C = 3.9e-16;
  double drum_speed = 6.7 / 60.0;
  double dt = 1e-5, t_end = 0.0;
  bool contact = false, json = false;
};

struct CalOpts {
  std::string data;
  nipdem::probe::RcFitOptions fit;
  bool json = false;
};

nipdem::cli::Register reg([](CLI::App& app) {
  auto* rc = nipdem::cli::group(app, "rc");
  auto* sub = rc->add_subcommand("response", "Amplitude and phase of the probe voltage vs frequency (eqs. 4.7.6-4.7.7)");
  auto o = std::make_shared<ResponseOpts>();
  sub->add_option("--R", o->p.R_ohm, "toner-assembly resistance R [ohm]")->required();
  sub->add_option("--Rd", o->p.Rd_ohm, "SiOx-layer resistance Rd [ohm]")->required();
  sub->add_option("--C", o->p.C_F, "toner-probe capacity C [F]")->required();
  sub->add_option("--Rm", o->p.Rm_ohm, "measurement resistance Rm [ohm]")->capture_default_str();
  sub->add_option("--voltage", o->voltage, "applied amplitude V [V]")->required();
  sub->add_option("--freq", o->freq, "frequencies F1:F2:STEP [Hz]")->required();
  sub->add_flag("--json", o->json, "print one JSON object on stdout");
  sub->callback([o] {
    // The checks and the table are those of Python's nipdem.rc_response (one library function).
    const auto table = nipdem::probe::rc_response_table(o->p, o->voltage, o->freq);
    nlohmann::json rows = nlohmann::json::array();
    if (!o->json) std::printf("%14s %16s %12s\n", "frequency_Hz", "amplitude_V", "phase_deg");
    for (const auto& r : table) {
      if (o->json) {
        rows.push_back({{"frequency_Hz", r.frequency_Hz}, {"amplitude_V", r.amplitude_V}, {"phase_deg", r.phase_deg()}});
      } else {
        std::printf("%14.6g %16.6e %12.6f\n", r.frequency_Hz, r.amplitude_V, r.phase_deg());
      }
    }
    if (o->json) {
      nlohmann::json j;
      j["rows"] = rows;
      j["R_ohm"] = o->p.R_ohm;
      j["Rd_ohm"] = o->p.Rd_ohm;
      j["C_F"] = o->p.C_F;
      j["Rm_ohm"] = o->p.Rm_ohm;
      j["voltage_V"] = o->voltage;
      nipdem::cli::print_json(j.dump());
    }
  });

  auto* ch = rc->add_subcommand("charge",
                                 "Capacitor voltage of one particle charged through a path R under a print pattern (§2.5.5)");
  auto q = std::make_shared<ChargeOpts>();
  ch->add_option("--pattern", q->pattern, "TOML file with a [print] table (see docs/charge-model.md)")->required();
  ch->add_option("--R", q->R, "path resistance [ohm]")->capture_default_str();
  auto* rd_opt = ch->add_option("--Rd", q->Rd, "toner-drum leak resistance when touching [ohm] (only with --contact)")
                     ->capture_default_str();
  ch->add_option("--C", q->C, "toner-drum capacity [F]")->capture_default_str();
  ch->add_option("--drum-speed", q->drum_speed, "drum surface speed [m/s] (CPS700: 6.7 m/min)")->capture_default_str();
  ch->add_option("--dt", q->dt, "output interval [s]")->capture_default_str();
  auto* t_end_opt = ch->add_option("--t-end", q->t_end, "end time [s] (default: 1.2 x the end of the last line)");
  ch->add_flag("--contact", q->contact, "particle touches the drum (leak through Rd)");
  ch->add_flag("--json", q->json, "print one JSON object on stdout");
  ch->callback([q, t_end_opt, rd_opt] {
    using namespace nipdem;
    const io::PrintPattern pat = io::load_print_pattern(q->pattern);
    // Ranges far beyond the thesis' (R ~ 6e11, Rd ~ 1.8e24 ohm, C ~ 4e-16 F, 6.7 m/min), the same
    // as rc response's, so that tau = R C and the voltages stay finite; named by option.
    require_range("rc charge", "--R", q->R, 1e-3, 1e30);
    require_range("rc charge", "--C", q->C, 1e-24, 1.0);
    if (rd_opt->count() > 0 && !q->contact)
      throw_input("rc charge", "--Rd", fmt::format("{:g}", q->Rd),
                  "has no effect without --contact (the leak through Rd exists only while the particle touches the drum)",
                  "--Rd together with --contact");
    require_range("rc charge", "--Rd", q->Rd, 1e-3, 1e40);
    require_range("rc charge", "--drum-speed", q->drum_speed, 1e-6, 100.0);
    require_positive("rc charge", "--dt", q->dt);
    const bool t_end_given = t_end_opt->count() > 0;
    if (t_end_given) require_positive("rc charge", "--t-end", q->t_end);  // 0 or less is not "the default"
    charge::RcChargeParams p;
    p.C_td_F = q->C;
    p.R_td_ohm = q->Rd;
    p.validate();
    double t_end = q->t_end;
    if (!t_end_given) {
      const double s_end = pat.segments().empty() ? 0.0 : pat.segments().back().end_m;
      t_end = 1.2 * std::max(s_end, 0.0) / q->drum_speed;
      if (t_end <= 0.0) t_end = 10 * q->R * q->C;
    }
    if (t_end / q->dt > 1e6)
      throw_input("rc charge", t_end_given ? "--dt, --t-end" : "--dt",
                  t_end_given ? fmt::format("{:g} s, {:g} s", q->dt, t_end) : fmt::format("{:g}", q->dt),
                  fmt::format("{:g} output rows up to t_end = {:g} s ({}), more than 1e6", t_end / q->dt, t_end,
                              t_end_given ? "--t-end" : "the default end: 1.2 x the end of the last line / --drum-speed"),
                  fmt::format(">= t_end/1e6 = {:g} s, or a shorter --t-end", t_end / 1e6));
    const auto coupling = q->contact ? charge::DrumCoupling::contact : charge::DrumCoupling::capacitor;
    nlohmann::json rows = nlohmann::json::array();
    double u = 0.0, t = 0.0;
    if (!q->json) std::printf("%14s %16s %14s\n", "time_s", "drum_voltage_V", "voltage_V");
    // Integrate exactly between pattern switching points (the drum voltage is piecewise constant).
    for (long k = 0; t <= t_end * (1 + 1e-12); ++k) {
      const double Vd = pat.voltage_at_time(t, q->drum_speed);
      if (q->json) rows.push_back({{"time_s", t}, {"drum_voltage_V", Vd}, {"voltage_V", u}});
      else std::printf("%14.6e %16.6g %14.6f\n", t, Vd, u);
      const double t_next = (k + 1) * q->dt;
      while (t < t_next) {
        const double s_sw = pat.next_switch_after(q->drum_speed * t) / q->drum_speed;
        double t_stop = std::min(t_next, s_sw);
        // A switch point s/v can round to a time whose drum position v t lies just before s: the
        // same switch would be found again without progress (a hang, e.g. --drum-speed 1e300).
        // Step one ulp past it instead; never reached when the division lands on or after s.
        if (!(t_stop > t)) t_stop = std::nextafter(t, t_next);
        u = charge::rc_update(u, pat.voltage_at_time(t, q->drum_speed), q->R, coupling, p, t_stop - t);
        t = t_stop;
      }
    }
    if (q->json) {
      nlohmann::json j;
      j["rows"] = rows;
      j["tau_s"] = charge::rc_time_constant(q->R, coupling, p);
      j["drum_speed_m_per_s"] = q->drum_speed;
      nipdem::cli::print_json(j.dump());
    }
  });

  auto* cal = nipdem::cli::group(app, "calibrate");
  auto* csub = cal->add_subcommand("rc", "Fit R, Rd, C of the probe circuit to amplitude/phase vs frequency (§4.7)");
  auto c = std::make_shared<CalOpts>();
  csub->add_option("--data", c->data, "CSV with columns frequency_Hz,amplitude_V,phase_deg")->required();
  csub->add_option("--voltage", c->fit.voltage_V, "applied amplitude V [V]")->capture_default_str();
  csub->add_option("--Rm", c->fit.Rm_ohm, "measurement resistance Rm [ohm]")->capture_default_str();
  csub->add_option("--particles", c->fit.particles,
                   "particles on the probe: measured amplitude = particles x model amplitude (thesis: ~1e5)")
      ->capture_default_str();
  csub->add_option("--amplitude-rel-std", c->fit.amplitude_rel_std, "known relative amplitude noise (0: estimate)")
      ->capture_default_str();
  csub->add_option("--phase-std-deg", c->fit.phase_std_deg, "known phase noise [deg] (0: estimate)")->capture_default_str();
  csub->add_flag("--json", c->json, "print one JSON object on stdout");
  csub->callback([c] {
    using nipdem::require_range;
    // Options by name before RcFitOptions::validate (which names the fields): the thesis' set-up
    // is 40 V, Rm = 10 kOhm, ~1e5 particles on the probe; the ranges leave wide margins.
    check_amplitude("calibrate rc", c->fit.voltage_V);
    require_range("calibrate rc", "--Rm", c->fit.Rm_ohm, 1e-3, 1e30);
    require_range("calibrate rc", "--particles", c->fit.particles, 1.0, 1e12);
    require_range("calibrate rc", "--amplitude-rel-std", c->fit.amplitude_rel_std, 0.0, 10.0);
    require_range("calibrate rc", "--phase-std-deg", c->fit.phase_std_deg, 0.0, 90.0);
    const auto data = nipdem::probe::read_rc_csv(c->data);
    // The circuit is a passive divider: one particle's amplitude is below the applied one.
    for (std::size_t i = 0; i < data.size(); ++i)
      if (!(data[i].amplitude_V < c->fit.particles * c->fit.voltage_V))
        nipdem::throw_input(c->data, fmt::format("data row {} ({:g} Hz) column amplitude_V", i + 1, data[i].frequency_Hz),
                            fmt::format("{:g}", data[i].amplitude_V),
                            fmt::format("not below --particles x --voltage = {:g} x {:g} V, which the circuit cannot produce",
                                        c->fit.particles, c->fit.voltage_V),
                            "(0, particles x voltage)");
    const auto r = nipdem::probe::fit_rc(data, c->fit);
    // A fit that ran into the search box or whose chi2/uncertainties are not finite has no
    // meaning (fit_rc then reports converged = false): the data do not fit the circuit for
    // these options.
    if (!r.limit_hit.empty() || !std::isfinite(r.chi2) || !std::isfinite(r.R_log_std) || !std::isfinite(r.C_log_std))
      nipdem::throw_input(c->data, "--particles, --voltage, --Rm",
                          fmt::format("{:g}, {:g} V, {:g} ohm", c->fit.particles, c->fit.voltage_V, c->fit.Rm_ohm),
                          fmt::format("the data cannot be fitted by the probe circuit ({})",
                                      r.limit_hit.empty() ? fmt::format("chi2 = {:g}, sd(ln R) = {:g}, sd(ln C) = {:g}", r.chi2,
                                                                        r.R_log_std, r.C_log_std)
                                                          : r.limit_hit),
                          "data whose amplitudes / --particles fit the circuit driven by --voltage with --Rm");
    if (c->json) {
      nlohmann::json j;
      j["R_ohm"] = r.R_ohm;
      j["Rd_ohm"] = r.Rd_ohm;
      j["C_F"] = r.C_F;
      j["R_ohm_std"] = r.R_ohm_std;
      j["Rd_ohm_std"] = finite_or_null(r.Rd_ohm_std);
      j["C_F_std"] = r.C_F_std;
      j["R_log_std"] = r.R_log_std;
      j["Rd_log_std"] = finite_or_null(r.Rd_log_std);
      j["C_log_std"] = r.C_log_std;
      j["Rd_ohm_lower_95"] = r.Rd_ohm_lower_95;
      j["Rd_ohm_upper_95"] = finite_or_null(r.Rd_ohm_upper_95);
      j["Rd_identifiable"] = r.Rd_identifiable;
      j["corr_R_C"] = r.corr_R_C;
      j["tau_s"] = r.tau_s;
      j["amplitude_rel_std"] = r.amplitude_rel_std;
      j["phase_std_deg"] = r.phase_std_deg;
      j["chi2"] = r.chi2;
      j["dof"] = r.dof;
      j["iterations"] = r.iterations;
      j["converged"] = r.converged;
      j["n_points"] = data.size();
      nipdem::cli::print_json(j.dump());
    } else {
      std::printf("R   = %.4e +- %.2e ohm\n", r.R_ohm, r.R_ohm_std);
      if (r.Rd_identifiable)
        std::printf("Rd  = %.4e +- %.2e ohm (95%%: %.3e .. %.3e)\n", r.Rd_ohm, r.Rd_ohm_std, r.Rd_ohm_lower_95, r.Rd_ohm_upper_95);
      else
        std::printf("Rd  : not identifiable from these data; Rd >= %.3e ohm (95%%)\n", r.Rd_ohm_lower_95);
      std::printf("C   = %.4e +- %.2e F\n", r.C_F, r.C_F_std);
      std::printf("tau = %.4e s   chi2 = %.3f (dof %d)  %s after %d iterations\n", r.tau_s, r.chi2, r.dof,
                  r.converged ? "converged" : "NOT converged", r.iterations);
    }
  });
});

}  // namespace
