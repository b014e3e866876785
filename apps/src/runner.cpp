#include "sewn/apps/runner.hpp"
#include "sewn/apps/checkpoint.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <memory>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "sewn/apps/continuum.hpp"
#include "sewn/io/write.hpp"
#include "sewn/physics/integrate/energy_ledger.hpp"
#include "sewn/physics/integrate/implicit_midpoint.hpp"
#include "sewn/physics/integrate/newton_euler.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/rods/rods_term.hpp"
#include "sewn/physics/solids/inversion.hpp"
#include "sewn/physics/solve/linear_solver.hpp"
#include "sewn/physics/threads.hpp"
#include "sewn/refine/cut.hpp"
#include "sewn/refine/hierarchy.hpp"

#include "run_build.hpp"
#include "run_checkpoint.hpp"
#include "run_output.hpp"

namespace sewn::app {

namespace {

using detail::Bodies;
using detail::frame_file;
using detail::Snapshot;
using detail::writing;
using physics::Index;
using Vec3d = Eigen::Vector3d;
using Clock = std::chrono::steady_clock;

// A semi-implicit step, its stable-step refusal told in the scene's terms: the user sets scene
// keys, not the library's enforce_stable_step.
void step_semi_implicit(physics::SymplecticEuler& semi, physics::System& sys, double h, double t, const Scene& scene) {
  try {
    (void)semi.step(sys, h);
  } catch (const physics::StabilityError& e) {
    char text[512];
    std::snprintf(text, sizeof text,
                  "%s: integrator.step: h = %.4g s is not below the semi-implicit stable-step bound %.4g s (at t = %.4g s). "
                  "Use a step below %.4g s, the implicit integrator (integrator.type = \"implicit\"), or set "
                  "integrator.allow_unstable = true to run it anyway; the run stopped there.",
                  scene.file.c_str(), h, e.bound(), t, e.bound());
    throw physics::StabilityError(text, e.step(), e.bound());
  }
}

// Keeps the facets a scheduled cut unsews, for a checkpoint to apply again.
void record_cut(std::vector<AppliedCut>& applied, std::size_t spec, std::span<const refine::Facet> facets) {
  AppliedCut a;
  a.spec = static_cast<std::uint32_t>(spec);
  for (const refine::Facet& f : facets) {
    a.darts.push_back(f.dart.index());
    a.betas.push_back(static_cast<std::uint8_t>(f.index));
  }
  applied.push_back(std::move(a));
}

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.0f s", s);
  else
    std::snprintf(buf, sizeof buf, "%d min %02d s", static_cast<int>(s / 60), static_cast<int>(s) % 60);
  return buf;
}

physics::SymplecticEulerOptions semi_options(const Scene& scene) {
  physics::SymplecticEulerOptions so;
  so.enforce_stable_step = !scene.allow_unstable;
  return so;
}

physics::ImplicitEulerOptions implicit_options(const Scene& scene) {
  physics::ImplicitEulerOptions o;
  // "ldlt" is Newton's own direct solve (scene.cpp refuses it with the other integrators)
  o.solver = scene.solver == "ldlt" ? physics::solve::Backend::automatic : physics::solve::parse_backend(scene.solver);
  o.cg_tolerance = scene.tolerance;
  o.cg_absolute_tolerance = scene.absolute_tolerance;
  o.cg_absolute_acceleration = scene.absolute_acceleration;
  o.cg_max_iterations = static_cast<int>(scene.max_iterations);
  return o;
}

physics::ImplicitMidpointOptions midpoint_options(const Scene& scene) {
  physics::ImplicitMidpointOptions o;
  o.cg_max_iterations = static_cast<int>(scene.max_iterations);
  return o;
}

physics::integrate::NewtonEulerOptions newton_options(const Scene& scene) {
  physics::integrate::NewtonEulerOptions o;
  o.velocity_tolerance = scene.newton_tolerance;
  o.max_iterations = static_cast<int>(scene.newton_iterations);
  o.cg_tolerance = scene.tolerance;
  o.cg_max_iterations = static_cast<int>(scene.max_iterations);
  o.cg_forcing_max = scene.newton_forcing;
  if (scene.solver == "ldlt" || scene.solver == "cholmod") o.solver = physics::integrate::LinearSolver::ldlt;
  if (scene.solver == "cholmod-pcg") o.solver = physics::integrate::LinearSolver::cholmod_pcg;
  return o;
}

// Whether the system simulates discrete elastic rods.
bool has_rods(const physics::System& sys) {
  for (const auto& t : sys.terms())
    if (dynamic_cast<const physics::rods::Rods*>(t.get()) != nullptr) return true;
  return false;
}

// What solver `auto` gives Newton, by the model's size (docs/solvers.md, "Newton's default").
// Elastic models are stiff against their mass: block-Jacobi CG took 440-1300 iterations a Newton
// system on the elastic scenes and beams, rods far more (a 16-edge helix at h = 10 ms: 519 a
// step; ~28 000 on a hanging rod), where a factorization solves exactly. Measured with
// `sewn run`: up to ~1000 nodes the direct `ldlt` was 3-13x faster than CG and on a par with
// `cholmod-pcg`; on a 6561-node solid cantilever `cholmod-pcg` (a factor kept across Newton
// iterations and steps) was 1.5x faster than `ldlt` and 4.8x than CG. Past the size where the
// implicit integrators' `auto` stops keeping a factor (8000 nodes: factors of hundreds of MB),
// CG, or `ldlt` with rods, which leave CG no chance.
constexpr physics::Index newton_direct_nodes = 2000;
constexpr physics::Index newton_kept_factor_nodes = 8000;

physics::integrate::LinearSolver newton_auto_solver(const physics::System& sys) {
  using physics::integrate::LinearSolver;
  const physics::Index nodes = sys.nodes().num_alive();
  if (nodes <= newton_direct_nodes) return LinearSolver::ldlt;
  if (nodes <= newton_kept_factor_nodes && physics::solve::available(physics::solve::Backend::cholmod_pcg))
    return LinearSolver::cholmod_pcg;
  return has_rods(sys) ? LinearSolver::ldlt : LinearSolver::cg;
}

// The warning for the first implicit step that created energy.
std::string energy_rise_text(std::uint64_t step, double h, const physics::EnergyRise& rise) {
  char msg[400];
  std::snprintf(msg, sizeof msg,
                "step %llu (t = %.6g s) raised the total energy from %.6g J to %.6g J (+%.3g %% of the %.6g J in "
                "motion) with no external work to supply it: the integrator created energy (the linearised "
                "implicit step does on fast rotations; a smaller step or integrator.type \"midpoint\" avoids it)",
                static_cast<unsigned long long>(step), static_cast<double>(step) * h, rise.before, rise.after,
                100 * (rise.after - rise.before) / rise.moved, rise.moved);
  return msg;
}

// The run's second phase: the bodies stepped to the end of the scene's time line, with its
// scheduled cuts, refinement, frames (.vtu, .pvd, frames.csv), checks (inversions, energy
// created) and checkpoints; resumed from a checkpoint when the options name one.
class RunLoop {
 public:
  RunLoop(const Scene& scene, const RunOptions& options, Bodies& bodies, RunSummary& sum);
  void run();

 private:
  void resume();
  void open_outputs();
  void restore_integrators();
  void apply_due_cuts(double t);
  refine::CutReport apply_cut(std::size_t k);
  int step(double t);
  // A blow-up's message with the particle it names told as its file numbers its point.
  [[nodiscard]] physics::BlowupError in_files(const physics::BlowupError& e) const;
  void check_energy(std::uint64_t step);
  void note_short_stop(double t, const physics::integrate::NewtonReport& rep);
  void refine_after(std::uint64_t step);
  void write_frame(double t);
  void write_csv_row(double t);
  void check_inversion(std::uint64_t step);
  void save_checkpoint(double wall);
  void draw_progress(std::uint64_t step);
  void finish();

  const Scene& scene_;
  const RunOptions& options_;
  Bodies& b_;
  physics::MssModel<3>& model_;
  RunSummary& sum_;

  // the time line: steps, frames and scheduled cuts as (time, index) in time order
  double h_;
  std::uint64_t steps_;
  std::uint32_t frames_;
  std::vector<std::pair<double, std::size_t>> cuts_;
  std::size_t next_cut_ = 0;  // the first scheduled cut not applied yet
  std::vector<AppliedCut> applied_;

  // a checkpoint to continue from (empty when starting afresh), and this run's identity
  const bool resuming_;
  Checkpoint ck_;
  std::uint64_t run_id_ = 0;
  std::uint32_t checkpoints_ = 0;

  // outputs and the per-frame record a checkpoint lists
  Snapshot snap_;
  std::unique_ptr<io::PvdWriter> pvd_;
  std::unique_ptr<io::CsvWriter> csv_;
  std::uint32_t frame_ = 0;
  double frame_ms_ = 0, frame_cg_sum_ = 0;
  int frame_cg_max_ = 0;
  std::uint64_t frame_steps_ = 0;
  std::vector<double> frame_times_, csv_rows_;

  // checks
  physics::EnergyLedger ledger_;
  physics::InversionMonitor inversions_;
  physics::Index inverted_now_ = 0;

  // integrators
  physics::SymplecticEuler semi_;
  physics::LinearlyImplicitEuler implicit_;
  physics::ImplicitMidpoint midpoint_;
  physics::integrate::NewtonEuler newton_;
  const bool use_midpoint_, use_implicit_, use_newton_;

  std::uint64_t steps_done_ = 0;
  bool bar_;
  Clock::time_point started_, last_bar_;
};

RunLoop::RunLoop(const Scene& scene, const RunOptions& options, Bodies& bodies, RunSummary& sum)
    : scene_(scene),
      options_(options),
      b_(bodies),
      model_(*bodies.model),
      sum_(sum),
      h_(scene.step),
      steps_(static_cast<std::uint64_t>(std::ceil(std::min(scene.duration, options.until.value_or(scene.duration)) / h_ - 1e-9))),
      frames_(options.frames.value_or(scene.frames)),
      resuming_(!options.resume.empty()),
      ledger_(scene.energy_rise_tolerance),
      semi_(semi_options(scene)),
      implicit_(implicit_options(scene)),
      midpoint_(midpoint_options(scene)),
      newton_(newton_options(scene)),
      use_midpoint_(scene.integrator == "midpoint"),
      use_implicit_(scene.integrator == "implicit" || use_midpoint_),
      use_newton_(scene.integrator == "newton"),
      bar_(!options.quiet && options.progress && isatty(STDERR_FILENO)) {
  if (use_newton_ && scene.solver == "auto") newton_.options().solver = newton_auto_solver(model_.system());
  for (std::size_t k = 0; k < scene.cuts.size(); ++k) cuts_.emplace_back(scene.cuts[k].time, k);
  std::stable_sort(cuts_.begin(), cuts_.end());
  if (resuming_ || options.checkpoint_every > 0) run_id_ = detail::run_hash(scene, model_, steps_, frames_);
  if (resuming_) resume();
  open_outputs();
  // Energy balance of every frame; each implicit step is checked for energy it created (the
  // semi-implicit scheme's plain energy oscillates by design: its divergence is the
  // integrator's watchdog's business).
  ledger_.start(model_.system());
  if (resuming_) ledger_.restore(ck_.ledger);
  frame_ = ck_.frame;
  frame_ms_ = ck_.frame_ms;
  frame_cg_sum_ = ck_.frame_cg_sum;
  frame_cg_max_ = ck_.frame_cg_max;
  frame_steps_ = ck_.frame_steps;
  frame_times_ = ck_.frame_times;
  csv_rows_ = ck_.csv_rows;
  sum_.cuts = ck_.cuts_applied;
  sum_.faces_cut = ck_.faces_cut;
  sum_.inverted_max = ck_.inverted_max;
  sum_.first_inversion = ck_.first_inversion;
  sum_.first_energy_rise = ck_.first_energy_rise;
  sum_.kinetic_max = ck_.kinetic_max;
  steps_done_ = ck_.step;
  applied_ = ck_.cuts;
}

// A checkpoint to continue from: this scene's run, its cuts applied again, its motion put back.
void RunLoop::resume() {
  const std::string file = options_.resume.string();
  ck_ = read_checkpoint(options_.resume);
  if (ck_.steps_total != steps_ || ck_.frames_total != frames_)
    throw CheckpointError(file, "written by a run of " + std::to_string(ck_.steps_total) + " steps and " +
                                    std::to_string(ck_.frames_total) + " frames, but this one has " + std::to_string(steps_) +
                                    " steps and " + std::to_string(frames_) + " frames (resume with the same --frames and --until)");
  if (ck_.run_hash != run_id_)
    throw CheckpointError(file, "written by another scene (" + scene_.file + " or its mesh files differ from the run's)");
  next_cut_ = detail::check_cut_schedule(ck_, cuts_, file);
  detail::restore_model(model_, b_.continuum, b_.joints, b_.refinement.get(), ck_, file);
  if (ck_.frame_times.size() != (scene_.write_vtu ? ck_.frame : 0) ||
      std::size_t{ck_.csv_columns} * ck_.frame != (scene_.write_csv ? ck_.csv_rows.size() : 0))
    throw CheckpointError(file, "its output record does not match its " + std::to_string(ck_.frame) + " frames");
  // the .pvd will list the frames written before the checkpoint: they must be there
  for (std::uint32_t f = 0; f < ck_.frame_times.size(); ++f)
    if (!std::filesystem::exists(sum_.out / frame_file(f)))
      throw CheckpointError(file, "its run wrote " + frame_file(f) + ", which " + sum_.out.string() +
                                      " does not hold: resume in the output folder the run wrote to");
  sum_.resumed_at = ck_.step;
}

void RunLoop::open_outputs() {
  if (scene_.write_vtu) {
    sum_.pvd = sum_.out / (scene_.name + ".pvd");
    std::vector<std::pair<double, std::string>> listed;
    for (std::uint32_t f = 0; f < ck_.frame_times.size(); ++f) listed.emplace_back(ck_.frame_times[f], frame_file(f));
    writing([&] { pvd_ = std::make_unique<io::PvdWriter>(sum_.pvd, std::move(listed)); });
  }
  if (scene_.write_csv) {
    sum_.csv = sum_.out / "frames.csv";
    const std::vector<std::string> columns{"frame", "time", "kinetic_energy", "elastic_energy", "gravity_energy",
                                           "total_energy", "external_work", "dissipated", "energy_ratio_max",
                                           "energy_rises", "inverted", "momentum_x", "momentum_y", "momentum_z",
                                           "angular_momentum_x", "angular_momentum_y", "angular_momentum_z", "particles", "springs", "elements", "steps", "ms_per_step",
                                           "cg_iterations_mean", "cg_iterations_max", "cuts", "faces_cut", "refined", "coarsened"};
    if (resuming_ && ck_.csv_columns != columns.size())
      throw CheckpointError(options_.resume.string(), "its frames.csv rows have " + std::to_string(ck_.csv_columns) + " columns, not " +
                                                         std::to_string(columns.size()));
    writing([&] {
      csv_ = std::make_unique<io::CsvWriter>(sum_.csv, columns);
      for (std::size_t r = 0; r < ck_.frame; ++r) csv_->row(std::span<const double>(ck_.csv_rows).subspan(r * columns.size(), columns.size()));
    });
  }
}

void RunLoop::restore_integrators() {
  try {
    semi_.restore(model_.system(), ck_.semi);
    implicit_.restore(model_.system(), ck_.implicit);
    midpoint_.restore(model_.system(), ck_.midpoint);
    if (use_newton_) newton_.restore(model_.system(), ck_.newton);
  } catch (const physics::InputError& e) {
    throw CheckpointError(options_.resume.string(), e.what());
  }
}

// Inverted elements: counted at every frame, and at every step when the scene stops at the
// first; the first seen is reported once.
void RunLoop::check_inversion(std::uint64_t step) {
  const physics::InversionCount c = inversions_.count(model_);
  inverted_now_ = c.elements;
  sum_.inverted_max = std::max<std::uint64_t>(sum_.inverted_max, c.elements);
  if (c.elements == 0 || !sum_.first_inversion.empty()) return;
  // the cell as its file names it: elements past the mesh's cells are children of refinement
  const Assembly& assembly = b_.assembly;
  const std::string cell = (c.first < assembly.mesh.num_cells() ? "" : "refined from ") + assembly.cell_name(c.first_cell, true);
  char when[100];
  std::snprintf(when, sizeof when, " is inverted at step %llu (t = %.6g s)", static_cast<unsigned long long>(step),
                static_cast<double>(step) * scene_.step);
  const std::string msg = "element " + std::to_string(c.first) + " (" + cell + ")" + when +
                          (c.elements > 1 ? ", with " + std::to_string(c.elements - 1) + " more" : "");
  sum_.first_inversion = msg;
  if (scene_.stop_on_inversion) throw std::runtime_error(std::string(msg) + "; stopped there (integrator.stop_on_inversion)");
  if (!options_.quiet) std::fprintf(stderr, "\nsewn: warning: %s\n", msg.c_str());
}

void RunLoop::write_frame(double t) {
  model_.system().compute_forces();
  check_inversion(steps_done_);
  if (pvd_) {
    snap_.take(model_);
    // rods: one poly-line each, their material frame (m1, m2) per node, zero off rods
    const RodOutput rods = rod_output(b_.continuum, model_);
    snap_.rods_as_poly_lines(b_.continuum, rods);
    const std::string name = frame_file(frame_);
    const io::DataArray point_data[] = {
        io::DataArray::vectors("velocity", snap_.velocity), io::DataArray::vectors("force", snap_.force),
        io::DataArray::vectors("displacement", snap_.displacement), io::DataArray::flags("fixed", snap_.fixed),
        io::DataArray::vectors("rod_m1", rods.m1), io::DataArray::vectors("rod_m2", rods.m2)};
    const io::DataArray cell_data[] = {io::DataArray::ints("material", snap_.material),
                                       io::DataArray::ints("refinement_level", snap_.level),
                                       io::DataArray::ints("mesh_cell", snap_.mesh_cell)};
    // the frame is complete on disk before the series lists it
    writing([&] {
      io::write_vtu(sum_.out / name, snap_.points, snap_.cells(), point_data, cell_data);
      pvd_->add(t, sum_.out / name);
    });
    frame_times_.push_back(t);
  }
  if (csv_) write_csv_row(t);
  ++frame_;
  frame_ms_ = frame_cg_sum_ = 0;
  frame_cg_max_ = 0;
  frame_steps_ = 0;
}

void RunLoop::write_csv_row(double t) {
  const physics::System& sys = model_.system();
  const auto elements = std::count_if(model_.elements().begin(), model_.elements().end(), [](const auto& e) { return e.alive; });
  const physics::EnergyBalance e = ledger_.balance(sys);
  ledger_.observe(e);
  const physics::Momenta p = physics::momenta(model_.nodes());
  const auto& refinement = b_.refinement;
  const double row[] = {static_cast<double>(frame_), t, e.kinetic, e.elastic, e.external_potential, e.total, e.external_work,
                        e.dissipated, ledger_.peak_ratio(), static_cast<double>(ledger_.rises()), static_cast<double>(inverted_now_),
                        p.linear.x(), p.linear.y(), p.linear.z(), p.angular.x(), p.angular.y(), p.angular.z(),
                        static_cast<double>(model_.nodes().num_alive()),
                        static_cast<double>(model_.springs().num_alive()), static_cast<double>(elements),
                        static_cast<double>(frame_steps_), frame_steps_ ? frame_ms_ / static_cast<double>(frame_steps_) : 0.0,
                        frame_steps_ ? frame_cg_sum_ / static_cast<double>(frame_steps_) : 0.0, static_cast<double>(frame_cg_max_),
                        static_cast<double>(sum_.cuts), static_cast<double>(sum_.faces_cut),
                        static_cast<double>(refinement ? refinement->refined() : 0),
                        static_cast<double>(refinement ? refinement->coarsened() : 0)};
  writing([&] { csv_->row(row); });
  csv_rows_.insert(csv_rows_.end(), std::begin(row), std::end(row));
}

// Everything the loop reads from earlier steps, in the order of checkpoint.hpp.
void RunLoop::save_checkpoint(double wall) {
  Checkpoint c;
  c.run_hash = run_id_;
  c.model_hash = detail::model_hash(model_);
  c.steps_total = steps_;
  c.frames_total = frames_;
  c.step = steps_done_;
  c.frame = frame_;
  c.cuts = applied_;
  c.x.assign(model_.nodes().x().begin(), model_.nodes().x().end());
  c.v.assign(model_.nodes().v().begin(), model_.nodes().v().end());
  c.semi = semi_.history(model_.system());
  if (use_implicit_ && !use_midpoint_) c.implicit = implicit_.history(model_.system());
  if (use_midpoint_) c.midpoint = midpoint_.history(model_.system());
  if (use_newton_) c.newton = newton_.history(model_.system());
  c.ledger = ledger_.state();
  if (b_.refinement) c.refinement = b_.refinement->state();
  if (b_.continuum.rods) c.rods = b_.continuum.rods->history();
  const physics::AngleTable& angles = model_.system().angles();
  c.angles.assign(angles.values().begin(), angles.values().end());
  c.angle_rates.assign(angles.rates().begin(), angles.rates().end());
  if (b_.joints.points) c.point_connections = b_.joints.points->history();
  if (b_.joints.curves) c.curve_connections = b_.joints.curves->history();
  c.frame_times = frame_times_;
  c.csv_columns = csv_ ? static_cast<std::uint32_t>(csv_->columns()) : 0;
  c.csv_rows = csv_rows_;
  c.frame_ms = frame_ms_;
  c.frame_cg_sum = frame_cg_sum_;
  c.frame_cg_max = frame_cg_max_;
  c.frame_steps = frame_steps_;
  c.cuts_applied = sum_.cuts;
  c.faces_cut = sum_.faces_cut;
  c.kinetic_start = sum_.kinetic_start;
  c.kinetic_max = sum_.kinetic_max;
  c.wall = wall;
  c.inverted_max = sum_.inverted_max;
  c.first_inversion = sum_.first_inversion;
  c.first_energy_rise = sum_.first_energy_rise;
  sum_.checkpoint = sum_.out / (scene_.name + ".checkpoint");
  writing([&] { write_checkpoint(sum_.checkpoint, c); });
  ++checkpoints_;
}

void RunLoop::apply_due_cuts(double t) {
  for (; next_cut_ < cuts_.size() && cuts_[next_cut_].first <= t + 1e-12 * h_; ++next_cut_) {
    const refine::CutReport rep = apply_cut(cuts_[next_cut_].second);
    if (scene_.model != "mass-spring") follow_cut(b_.continuum, model_);
    sum_.faces_cut += rep.facets;
    ++sum_.cuts;
    ledger_.rebase(model_.system());
  }
}

// Scheduled cut k, recorded for a checkpoint to apply again. Throws SceneError for a cut that
// finds nothing to cut at its time.
refine::CutReport RunLoop::apply_cut(std::size_t k) {
  const CutSpec& c = scene_.cuts[k];
  const std::string path = "cuts[" + std::to_string(k) + "]";
  std::vector<refine::Facet> facets;
  if (c.type == "plane") {
    refine::Region within;
    if (c.within) within = [sel = *c.within](const Vec3d& p) { return sel.contains(detail::to_vec3(p)); };
    facets = refine::facets_across_plane(model_, Vec3d(c.point[0], c.point[1], c.point[2]), Vec3d(c.normal[0], c.normal[1], c.normal[2]),
                                         within);
    if (facets.empty()) throw SceneError(scene_.file, path, "the plane crosses no face between two elements (at its time)");
  } else if (c.type == "faces") {
    try {
      facets = refine::facets_with_points(model_, c.faces);
    } catch (const physics::InputError& e) {
      throw SceneError(scene_.file, path + ".faces", e.what());
    }
  } else if (c.type == "particles") {
    facets = refine::facets_among_points(model_, c.particles);
    if (facets.empty()) throw SceneError(scene_.file, path + ".particles", "no face between two elements has all its points among them");
  } else if (c.type == "pierce") {
    std::vector<Index> elements;
    for (Index e = 0; e < model_.elements().size(); ++e) {
      const auto& el = model_.elements()[e];
      if (el.alive && detail::selects_cell(c.where, b_.assembly.mesh, el.mesh_cell)) elements.push_back(e);
    }
    if (elements.empty()) throw SceneError(scene_.file, path + ".where", "selects no element (at its time)");
    applied_.push_back({static_cast<std::uint32_t>(k), true, c.remove, {}, {}, {elements.begin(), elements.end()}, 0});
    return refine::pierce(model_, elements, c.remove);
  } else {
    return {};
  }
  record_cut(applied_, k, facets);
  return refine::cut(model_, facets);
}

// One step of the scene's integrator; returns its linear-solver iterations.
int RunLoop::step(double t) {
  physics::System& sys = model_.system();
  if (!b_.motion.empty()) b_.motion.drive(model_.nodes(), t, h_);
  if (use_midpoint_) {
    const int cg = midpoint_.step(sys, h_).cg_iterations;
    if (midpoint_.last_substeps() > 1) {
      ++sum_.substepped;
      sum_.most_substeps = std::max(sum_.most_substeps, midpoint_.last_substeps());
    }
    return cg;
  }
  if (use_implicit_) return implicit_.step(sys, h_).cg_iterations;
  if (use_newton_) {
    const auto rep = newton_.step(sys, h_);
    sum_.newton_iterations += static_cast<std::uint64_t>(rep.iterations);
    note_short_stop(t, rep);
    return rep.linear_iterations;
  }
  step_semi_implicit(semi_, sys, h_, t, scene_);
  return 0;
}

// Newton's test reads the step, so it can pass while Newton crawls far from the solution: a rod
// pinned at one end, released horizontal and stepped at h = 10 s with newton_tolerance 1e-3 m/s
// stopped at 9 % of its fall, at the iteration after a line search cut its step to α = 3e-5. In
// the repository's Newton scenes the iteration before the stop always took its whole step.
void RunLoop::note_short_stop(double t, const physics::integrate::NewtonReport& rep) {
  if (!(rep.last_alpha < 0.25) || sum_.newton_short_stops++ > 0) return;
  char msg[600];
  std::snprintf(msg, sizeof msg,
                "the Newton step at t = %.6g s stopped %d iteration(s) in, right after its line search had cut the step to "
                "%.3g of its length: far from the solution Newton can move by less than newton_tolerance x h an "
                "iteration while still crawling, so this step may have stopped short; tighten integrator.newton_tolerance "
                "(and raise newton_iterations) or shorten the step to check",
                t, rep.iterations, rep.last_alpha);
  sum_.first_newton_short_stop = msg;
  if (!options_.quiet) std::fprintf(stderr, "%ssewn: warning: %s\n", bar_ ? "\n" : "", msg);
}

physics::BlowupError RunLoop::in_files(const physics::BlowupError& e) const {
  const Index i = e.node();
  if (i == physics::invalid_index || i >= model_.nodes().size()) return e;
  const std::uint32_t p = model_.point_of_node(i);
  // a cut's copy of a particle keeps its point; refinement's new particles have none
  const std::string where = p < b_.assembly.mesh.num_points() ? "is a particle at " + b_.assembly.point_name(p, true)
                                                               : "was added by refinement (no mesh point)";
  return physics::BlowupError(std::string(e.what()) + "; node " + std::to_string(i) + " " + where, i, e.quantity(), e.step(),
                              e.suggested_step());
}

void RunLoop::check_energy(std::uint64_t step) {
  if (!use_implicit_) return;
  const auto rise = ledger_.after_step(model_.system(), step);
  if (!rise || ledger_.rises() != 1) return;
  sum_.first_energy_rise = energy_rise_text(step, h_, *rise);
  if (!options_.quiet) std::fprintf(stderr, "%ssewn: warning: %s\n", bar_ ? "\n" : "", sum_.first_energy_rise.c_str());
}

// Refinement changes the elastic energy (new springs at their rest lengths under load) and
// coarsening dissipates the fine motion: after the step's energy check, the ledger restarts.
void RunLoop::refine_after(std::uint64_t step) {
  if (!b_.refinement) return;
  const auto r0 = Clock::now();
  if (b_.refinement->after_step(model_, static_cast<double>(step) * h_)) {
    ledger_.rebase(model_.system());
    // kept in order with the cuts, for a checkpoint to do them again
    for (const std::uint8_t kind : {std::uint8_t{1}, std::uint8_t{2}}) {
      const auto& elements = kind == 1 ? b_.refinement->last_refined() : b_.refinement->last_coarsened();
      if (!elements.empty()) applied_.push_back({0, false, false, {}, {}, {elements.begin(), elements.end()}, kind});
    }
  }
  frame_ms_ += std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
}

void RunLoop::draw_progress(std::uint64_t step) {
  if (!bar_ || (Clock::now() - last_bar_ <= std::chrono::milliseconds(100) && step != steps_)) return;
  last_bar_ = Clock::now();
  const double elapsed = std::chrono::duration<double>(last_bar_ - started_).count();
  const double done = static_cast<double>(step) / static_cast<double>(steps_);
  const int width = 30, filled = static_cast<int>(done * width);
  std::fprintf(stderr, "\r[%s%s] frame %u/%u  t = %.4g s  ETA %s  %.3g ms/step   ", std::string(static_cast<std::size_t>(filled), '#').c_str(),
               std::string(static_cast<std::size_t>(width - filled), '.').c_str(), frame_ - 1, frames_,
               static_cast<double>(step) * h_, format_seconds(elapsed / done * (1 - done)).c_str(),
               elapsed * 1e3 / static_cast<double>(step));
}

void RunLoop::run() {
  if (resuming_) {
    restore_integrators();
    sum_.kinetic_start = ck_.kinetic_start;
  } else {
    sum_.kinetic_start = model_.system().kinetic_energy();
    write_frame(0.0);
  }
  started_ = last_bar_ = Clock::now();
  for (std::uint64_t s = ck_.step; s < steps_; ++s) {
    const double t = static_cast<double>(s) * h_;
    const auto t0 = Clock::now();
    const std::clock_t c0 = std::clock();
    apply_due_cuts(t);
    int cg = 0;
    try {
      cg = step(t);
    } catch (const physics::BlowupError& e) {
      throw in_files(e);
    }
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    sum_.stepping += ms / 1e3;
    sum_.stepping_cpu += static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    sum_.linear_iterations += static_cast<std::uint64_t>(cg);
    frame_ms_ += ms;
    frame_cg_sum_ += cg;
    frame_cg_max_ = std::max(frame_cg_max_, cg);
    ++frame_steps_;
    steps_done_ = s + 1;
    if (scene_.stop_on_inversion) check_inversion(s + 1);
    check_energy(s + 1);
    refine_after(s + 1);
    sum_.kinetic_max = std::max(sum_.kinetic_max, model_.system().kinetic_energy());
    // frame f is written after step round(f · steps / frames)
    const auto due = static_cast<std::uint64_t>(std::llround(static_cast<double>(frame_) * static_cast<double>(steps_) / frames_));
    if (s + 1 >= due && frame_ <= frames_) {
      write_frame(static_cast<double>(s + 1) * h_);
      if (options_.checkpoint_every > 0 && (frame_ - 1) % options_.checkpoint_every == 0) {
        save_checkpoint(ck_.wall + std::chrono::duration<double>(Clock::now() - started_).count());
        if (checkpoints_ == options_.stop_after_checkpoints) {
          sum_.stopped = true;
          break;
        }
      }
    }
    draw_progress(s + 1);
  }
  if (bar_) std::fputc('\n', stderr);
  finish();
}

void RunLoop::finish() {
  sum_.wall = ck_.wall + std::chrono::duration<double>(Clock::now() - started_).count();
  sum_.steps = steps_done_;
  sum_.frames = frame_;
  sum_.simulated = static_cast<double>(steps_done_) * h_;
  sum_.ms_per_step = steps_done_ ? sum_.wall * 1e3 / static_cast<double>(steps_done_) : 0;
  sum_.kinetic_end = model_.system().kinetic_energy();
  if (csv_) writing([&] { csv_->flush(); });
  sum_.energy_rises = ledger_.rises();
  if (b_.refinement) {
    sum_.refined = b_.refinement->refined();
    sum_.coarsened = b_.refinement->coarsened();
  }
  if (!sum_.stopped && scene_.write_picture)
    sum_.picture = detail::write_picture(scene_, sum_.simulated, sum_.out, b_.assembly.mesh, model_, snap_);
}

}  // namespace

RunSummary run(const Scene& scene, const RunOptions& options) {
  RunSummary sum;
  sum.out = options.out.empty() ? std::filesystem::path("out") / scene.name : options.out;
  detail::prepare_output(sum.out);
  Bodies bodies = detail::build_bodies(scene, options.quiet, sum);
  // stepping runs on the scene's thread count, or SEWN_THREADS's (a bad value is named here)
  if (scene.threads > 0)
    physics::set_thread_count(static_cast<int>(scene.threads));
  else
    (void)physics::thread_count();
  RunLoop(scene, options, bodies, sum).run();
  return sum;
}

}  // namespace sewn::app
