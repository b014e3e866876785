#include "sewn/apps/checkpoint.hpp"

#include <bit>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <type_traits>

#include "sewn/io/atomic_file.hpp"

namespace sewn::app {

namespace {

static_assert(std::endian::native == std::endian::little, "checkpoints are written little-endian, as the machine's own order");

constexpr std::string_view magic = "SEWNCKPT";
constexpr std::size_t header_size = 8 + 4 + 4 + 8 + 8;

// Appends fixed-size values and length-prefixed arrays.
class Encoder {
 public:
  template <class T>
    requires std::is_arithmetic_v<T>
  void put(T value) {
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    out_.append(b, sizeof(T));
  }
  template <class T>
  void put(const std::vector<T>& values) {
    put(static_cast<std::uint64_t>(values.size()));
    if (!values.empty()) out_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  void put(const std::string& s) {
    put(static_cast<std::uint64_t>(s.size()));
    out_ += s;
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

// Reads what Encoder wrote, refusing (with the field's name) any read past the end and any
// array longer than the bytes left could hold.
class Decoder {
 public:
  Decoder(std::string_view bytes, const std::string& file) : in_(bytes), file_(file) {}

  template <class T>
    requires std::is_arithmetic_v<T>
  T get(const char* what) {
    need(sizeof(T), what);
    T value;
    std::memcpy(&value, in_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  bool flag(const char* what) {
    const auto b = get<std::uint8_t>(what);
    if (b > 1) fail(std::string(what) + " is " + std::to_string(b) + ", not a flag (0 or 1)");
    return b == 1;
  }
  template <class T>
  void get(std::vector<T>& out, const char* what) {
    const auto n = get<std::uint64_t>(what);
    if (n > (in_.size() - at_) / sizeof(T))
      fail(std::string(what) + " claims " + std::to_string(n) + " values, more than the " + std::to_string(in_.size() - at_) +
           " bytes left hold");
    out.resize(static_cast<std::size_t>(n));
    if (n > 0) std::memcpy(out.data(), in_.data() + at_, out.size() * sizeof(T));  // an empty vector's data() may be null
    at_ += out.size() * sizeof(T);
  }
  void get(std::string& out, const char* what) {
    std::vector<char> chars;
    get(chars, what);
    out.assign(chars.begin(), chars.end());
  }
  /// A count of items of at least `min_bytes` each, checked against the bytes left.
  std::size_t count(const char* what, std::size_t min_bytes) {
    const auto n = get<std::uint64_t>(what);
    if (n > (in_.size() - at_) / min_bytes)
      fail(std::string(what) + " claims " + std::to_string(n) + " items, more than the " + std::to_string(in_.size() - at_) +
           " bytes left hold");
    return static_cast<std::size_t>(n);
  }
  void finish() {
    if (at_ != in_.size()) fail(std::to_string(in_.size() - at_) + " bytes follow the last field");
  }
  [[noreturn]] void fail(const std::string& reason) const {
    throw CheckpointError(file_, "corrupt checkpoint: " + reason + " (at byte " + std::to_string(header_size + at_) + ")");
  }

 private:
  void need(std::size_t n, const char* what) const {
    if (in_.size() - at_ < n) fail(std::string("truncated in ") + what);
  }
  std::string_view in_;
  std::size_t at_ = 0;
  const std::string& file_;
};

void put_watchdog(Encoder& e, const physics::EnergyWatchdog::State& w) {
  e.put<std::uint8_t>(w.has_baseline);
  e.put<std::uint8_t>(w.baseline_current);
  e.put(w.internal0);
  e.put(w.external0);
  e.put(w.speed_at_check);
  e.put(w.peak_speed);
}

physics::EnergyWatchdog::State get_watchdog(Decoder& d) {
  physics::EnergyWatchdog::State w;
  w.has_baseline = d.flag("watchdog baseline flag");
  w.baseline_current = d.flag("watchdog current flag");
  w.internal0 = d.get<double>("watchdog internal energy");
  w.external0 = d.get<double>("watchdog external energy");
  w.speed_at_check = d.get<double>("watchdog speed");
  w.peak_speed = d.get<double>("watchdog peak speed");
  return w;
}

void put_solver(Encoder& e, const physics::solve::SolverState& s) {
  e.put(s.factored);
  e.put<std::uint8_t>(s.refresh_due);
  e.put(s.cycle_solves);
  e.put(s.cycle_iterations);
}

physics::solve::SolverState get_solver(Decoder& d) {
  physics::solve::SolverState s;
  d.get(s.factored, "factored matrix");
  s.refresh_due = d.flag("factorization refresh flag");
  s.cycle_solves = d.get<std::uint64_t>("solves since the factorization");
  s.cycle_iterations = d.get<std::uint64_t>("iterations since the factorization");
  return s;
}

void put_vec3s(Encoder& e, const std::vector<physics::rods::Vec3>& v) {
  std::vector<double> flat;
  for (const auto& p : v) flat.insert(flat.end(), {p.x(), p.y(), p.z()});
  e.put(flat);
}

std::vector<physics::rods::Vec3> get_vec3s(Decoder& d, const char* what, std::size_t expected) {
  std::vector<double> flat;
  d.get(flat, what);
  if (flat.size() != 3 * expected)
    d.fail(std::string(what) + ": " + std::to_string(flat.size()) + " coordinates for " + std::to_string(expected) + " edges");
  std::vector<physics::rods::Vec3> v;
  for (std::size_t k = 0; k < flat.size(); k += 3) v.emplace_back(flat[k], flat[k + 1], flat[k + 2]);
  return v;
}

void put_rods(Encoder& e, const std::vector<physics::rods::Rods::RodHistory>& rods) {
  e.put(static_cast<std::uint64_t>(rods.size()));
  for (const auto& r : rods) {
    e.put(r.rod.theta);
    put_vec3s(e, r.rod.tangent);
    put_vec3s(e, r.rod.director);
    e.put(r.rod.reference_twist);
    e.put(r.solved_at);
  }
}

std::vector<physics::rods::Rods::RodHistory> get_rods(Decoder& d) {
  std::vector<physics::rods::Rods::RodHistory> rods(d.count("rods", 5 * 8));
  for (auto& r : rods) {
    d.get(r.rod.theta, "rod angles");
    r.rod.tangent = get_vec3s(d, "rod tangents", r.rod.theta.size());
    r.rod.director = get_vec3s(d, "rod directors", r.rod.theta.size());
    d.get(r.rod.reference_twist, "rod reference twists");
    d.get(r.solved_at, "rod solve positions");
    if (r.solved_at.size() % 3 != 0) d.fail(std::to_string(r.solved_at.size()) + " rod solve coordinates (3 per vertex)");
  }
  return rods;
}

std::string encode_payload(const Checkpoint& c) {
  Encoder e;
  e.put(c.run_hash);
  e.put(c.model_hash);
  e.put(c.steps_total);
  e.put(c.frames_total);
  e.put(c.step);
  e.put(c.frame);
  e.put(static_cast<std::uint64_t>(c.cuts.size()));
  for (const AppliedCut& a : c.cuts) {
    e.put(a.spec);
    e.put<std::uint8_t>(a.pierce);
    e.put<std::uint8_t>(a.remove);
    e.put(a.refinement);
    e.put(a.darts);
    e.put(a.betas);
    e.put(a.elements);
  }
  e.put(c.x);
  e.put(c.v);
  const auto& b = c.semi.bound;
  e.put(b.h_max);
  e.put(b.stiffness_bound);
  e.put(b.damping_bound);
  e.put(b.stiffness_node);
  e.put(b.damping_node);
  e.put<std::uint8_t>(c.semi.bound_current);
  e.put(c.semi.steps);
  e.put(c.semi.bound_step);
  put_watchdog(e, c.semi.watchdog);
  e.put(c.implicit.warm_start);
  e.put(c.implicit.steps);
  put_watchdog(e, c.implicit.watchdog);
  put_solver(e, c.implicit.solver);
  e.put(c.midpoint.steps);
  put_watchdog(e, c.midpoint.watchdog);
  put_solver(e, c.newton.solver);
  e.put<std::uint8_t>(c.newton.direct_failed);
  const auto& l = c.ledger;
  for (double x : {l.total0, l.external0, l.last_total, l.last_moving, l.last_external}) e.put(x);
  e.put(l.rises);
  e.put(l.peak_ratio);
  put_rods(e, c.rods);
  e.put(c.angles);
  e.put(c.angle_rates);
  e.put(c.point_connections);
  e.put(c.curve_connections);
  e.put(c.refinement.refined);
  e.put(c.refinement.coarsened);
  e.put(c.refinement.dissipated);
  e.put(c.refinement.calm);
  e.put(c.frame_times);
  e.put(c.csv_columns);
  e.put(c.csv_rows);
  e.put(c.frame_ms);
  e.put(c.frame_cg_sum);
  e.put(c.frame_cg_max);
  e.put(c.frame_steps);
  e.put(c.cuts_applied);
  e.put(c.faces_cut);
  e.put(c.kinetic_start);
  e.put(c.kinetic_max);
  e.put(c.wall);
  e.put(c.inverted_max);
  e.put(c.first_inversion);
  e.put(c.first_energy_rise);
  return e.take();
}

Checkpoint decode_payload(Decoder& d) {
  Checkpoint c;
  c.run_hash = d.get<std::uint64_t>("run hash");
  c.model_hash = d.get<std::uint64_t>("model hash");
  c.steps_total = d.get<std::uint64_t>("step count");
  c.frames_total = d.get<std::uint32_t>("frame count");
  c.step = d.get<std::uint64_t>("steps done");
  c.frame = d.get<std::uint32_t>("frames done");
  c.cuts.resize(d.count("applied cuts", 4 + 3 + 3 * 8));
  for (AppliedCut& a : c.cuts) {
    a.spec = d.get<std::uint32_t>("cut index");
    a.pierce = d.flag("pierce flag");
    a.remove = d.flag("remove flag");
    a.refinement = d.get<std::uint8_t>("refinement kind");
    if (a.refinement > 2) d.fail("refinement kind " + std::to_string(a.refinement) + " (0 to 2)");
    d.get(a.darts, "cut darts");
    d.get(a.betas, "cut betas");
    d.get(a.elements, "edited elements");
    if (a.darts.size() != a.betas.size()) d.fail("a cut lists " + std::to_string(a.darts.size()) + " darts but " +
                                                 std::to_string(a.betas.size()) + " beta indices");
    if (a.refinement != 0 && (a.pierce || !a.darts.empty())) d.fail("a refinement or coarsening that also cuts or pierces");
  }
  d.get(c.x, "positions");
  d.get(c.v, "velocities");
  if (c.x.size() != c.v.size() || c.x.size() % 3 != 0)
    d.fail(std::to_string(c.x.size()) + " position and " + std::to_string(c.v.size()) + " velocity values (3 per particle each)");
  auto& b = c.semi.bound;
  b.h_max = d.get<double>("stable step");
  b.stiffness_bound = d.get<double>("stiffness bound");
  b.damping_bound = d.get<double>("damping bound");
  b.stiffness_node = d.get<physics::Index>("stiffness node");
  b.damping_node = d.get<physics::Index>("damping node");
  c.semi.bound_current = d.flag("stable step flag");
  c.semi.steps = d.get<std::uint64_t>("semi-implicit steps");
  c.semi.bound_step = d.get<std::uint64_t>("stable step's step");
  c.semi.watchdog = get_watchdog(d);
  d.get(c.implicit.warm_start, "warm start");
  c.implicit.steps = d.get<std::uint64_t>("implicit steps");
  c.implicit.watchdog = get_watchdog(d);
  c.implicit.solver = get_solver(d);
  c.midpoint.steps = d.get<std::uint64_t>("midpoint steps");
  c.midpoint.watchdog = get_watchdog(d);
  c.newton.solver = get_solver(d);
  c.newton.direct_failed = d.flag("Newton's direct factorization failure flag");
  auto& l = c.ledger;
  for (double* x : {&l.total0, &l.external0, &l.last_total, &l.last_moving, &l.last_external}) *x = d.get<double>("energy ledger");
  l.rises = d.get<std::uint64_t>("energy rises");
  l.peak_ratio = d.get<double>("energy peak ratio");
  c.rods = get_rods(d);
  d.get(c.angles, "angles");
  d.get(c.angle_rates, "angle rates");
  if (c.angles.size() != c.angle_rates.size())
    d.fail(std::to_string(c.angles.size()) + " angles but " + std::to_string(c.angle_rates.size()) + " angle rates");
  d.get(c.point_connections, "point connection history");
  d.get(c.curve_connections, "curve connection history");
  c.refinement.refined = d.get<std::uint64_t>("refinements");
  c.refinement.coarsened = d.get<std::uint64_t>("coarsenings");
  c.refinement.dissipated = d.get<double>("coarsening dissipation");
  d.get(c.refinement.calm, "calm counters");
  d.get(c.frame_times, "frame times");
  c.csv_columns = d.get<std::uint32_t>("csv columns");
  d.get(c.csv_rows, "csv rows");
  if (c.csv_columns == 0 ? !c.csv_rows.empty() : c.csv_rows.size() % c.csv_columns != 0)
    d.fail(std::to_string(c.csv_rows.size()) + " csv values are not whole rows of " + std::to_string(c.csv_columns));
  c.frame_ms = d.get<double>("frame time");
  c.frame_cg_sum = d.get<double>("frame iterations");
  c.frame_cg_max = d.get<std::int32_t>("frame iteration peak");
  c.frame_steps = d.get<std::uint64_t>("frame steps");
  c.cuts_applied = d.get<std::uint32_t>("cuts applied");
  c.faces_cut = d.get<std::uint32_t>("faces cut");
  c.kinetic_start = d.get<double>("initial kinetic energy");
  c.kinetic_max = d.get<double>("peak kinetic energy");
  c.wall = d.get<double>("wall time");
  c.inverted_max = d.get<std::uint64_t>("inversion peak");
  d.get(c.first_inversion, "first inversion");
  d.get(c.first_energy_rise, "first energy rise");
  d.finish();
  if (c.step > c.steps_total || c.frame > c.frames_total + 1)
    d.fail("step " + std::to_string(c.step) + " of " + std::to_string(c.steps_total) + ", frame " + std::to_string(c.frame) +
           " of " + std::to_string(c.frames_total) + " do not fit together");
  return c;
}

}  // namespace

std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

std::string encode_checkpoint(const Checkpoint& c) {
  const std::string payload = encode_payload(c);
  Encoder head;
  for (char ch : magic) head.put(ch);
  head.put(Checkpoint::format_version);
  head.put(std::uint32_t{0});
  head.put(static_cast<std::uint64_t>(payload.size()));
  head.put(fnv1a(payload));
  return head.take() + payload;
}

Checkpoint decode_checkpoint(std::string_view bytes, const std::string& file) {
  if (bytes.size() < magic.size() || bytes.substr(0, magic.size()) != magic)
    throw CheckpointError(file, "not a Sewn checkpoint (it does not start with \"SEWNCKPT\")");
  if (bytes.size() < header_size)
    throw CheckpointError(file, "truncated: " + std::to_string(bytes.size()) + " bytes, shorter than the " +
                                    std::to_string(header_size) + "-byte header");
  Decoder head(bytes.substr(magic.size(), header_size - magic.size()), file);
  const auto version = head.get<std::uint32_t>("version");
  const auto reserved = head.get<std::uint32_t>("reserved");
  const auto size = head.get<std::uint64_t>("payload size");
  const auto checksum = head.get<std::uint64_t>("checksum");
  if (version != Checkpoint::format_version)
    throw CheckpointError(file, "format version " + std::to_string(version) + ", but this sewn reads version " +
                                    std::to_string(Checkpoint::format_version) + " only");
  if (reserved != 0) throw CheckpointError(file, "corrupt checkpoint: the header's reserved field is not 0");
  const std::string_view payload = bytes.substr(header_size);
  if (payload.size() != size)
    throw CheckpointError(file, (payload.size() < size ? "truncated: " : "corrupt checkpoint: ") + std::to_string(payload.size()) +
                                    " bytes of data where the header announces " + std::to_string(size));
  if (fnv1a(payload) != checksum) throw CheckpointError(file, "corrupt checkpoint: the checksum does not match its data");
  Decoder d(payload, file);
  return decode_payload(d);
}

void write_checkpoint(const std::filesystem::path& path, const Checkpoint& c) {
  io::write_file_atomically(path, encode_checkpoint(c));
}

Checkpoint read_checkpoint(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw CheckpointError(path.string(), "is a folder, not a checkpoint file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CheckpointError(path.string(), std::string("cannot be opened: ") + std::strerror(errno));
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw CheckpointError(path.string(), "cannot be read");
  return decode_checkpoint(bytes, path.string());
}

}  // namespace sewn::app
