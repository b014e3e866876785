#include "sewn/apps/refine_keys.hpp"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "sewn/physics/errors.hpp"
#include "sewn/refine/criteria.hpp"
#include "sewn/refine/criterion.hpp"
#include "sewn/refine/hierarchy.hpp"

namespace sewn::app {

namespace {

constexpr int max_level_index = 8;  // a root hexahedron of level 1 becomes 8^7 = 2.1 M leaves

Field criterion_schema() {
  Field c = field("criterion", Kind::object);
  c.doc("When an element is refined (once per step at most) and when its family may be coarsened.").select_by("type");
  c.members({field("type", Kind::string).required().doc("Kind of criterion.")});
  c.variant("diagonal_strain",
            "The 2014 paper's: refine when a diagonal spring of the element has 100·|l − l₀|/l₀ above the threshold; "
            "coarsening allowed below half of it.",
            {field("threshold", Kind::number).unit("%").required().above(0).below(100).doc("Strain threshold (the paper: 1.2 for its beam, 2 in 2D).")});
  c.variant("strain_energy",
            "Refine when the element's strain energy density (½k(l − l₀)² of its own springs, sides and diagonals, over its rest volume) "
            "is above the threshold; coarsening allowed below a quarter of it (half the strain).",
            {field("threshold", Kind::number).unit("J/m³").required().above(0).doc("Energy density threshold (E·ε²/2 for a strain ε of a material of Young's modulus E, roughly).")});
  c.variant("region", "Refine the elements whose rest centroid is in a region (fixed in the material); coarsening allowed outside it.",
            {selector_schema("where", "The region: all, box or sphere.").required()});
  c.variant("point", "Refine the elements whose current centroid is within a radius of a point; coarsening allowed beyond twice the radius.",
            {field("point", Kind::vec3).unit("m").required().doc("The point."),
             field("radius", Kind::number).unit("m").required().above(0).doc("Radius.")});
  c.variant("contact", "Refine the elements with a particle inside one of the scene's `obstacles`; coarsening allowed when none is.", {});
  return c;
}

Selector geometric_selector(const nlohmann::json& j, const Field& schema, const std::string& file, const std::string& path) {
  Selector s = read_selector(j, schema);
  if (s.type == Selector::Type::tag || s.type == Selector::Type::points)
    throw SceneError(file, path + ".type", "refinement regions are geometric (all, box or sphere): refined elements carry no mesh tag or point list");
  return s;
}

Eigen::Vector3d to_eigen(const Vec3& v) { return {v[0], v[1], v[2]}; }

refine::InRegion<3>::Predicate region_predicate(const Selector& s) {
  return [s](const Eigen::Vector3d& p) { return s.contains({p.x(), p.y(), p.z()}); };
}

// What sewn::refine splits regularly: hexahedra 1:8, quads (membranes) 1:4.
bool refinable(const physics::Element& el) {
  return el.alive && (el.kind == physics::ElementKind::hexahedron || el.kind == physics::ElementKind::quad);
}

std::string count_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

}  // namespace

Field refinement_schema() {
  Field pre = field("pre_refine", Kind::object);
  pre.doc("Hexahedra and quads refined before the run.")
      .members({selector_schema("where", "The hexahedra and quads whose rest centroid lies here (all, box or sphere).").required(),
                field("levels", Kind::integer).fallback(1).at_least(1).at_most(max_level_index - 1)
                    .doc("Times refined (each 1:8, or 1:4 for a quad): the elements end at level index 1 + levels, within `max_level`.")});
  Field r = field("refinement", Kind::object);
  r.doc("Hierarchical adaptive refinement of the hexahedra and quads (membranes) of a mass-spring model (the 2014 paper; docs/refinement.md): "
        "after every step, each element a criterion picks is split 1:8 (a quad 1:4; at most one level per element per step, "
        "never past `max_level`), T-junctions become slave particles, and with `coarsen` calm families merge back "
        "into their parent. The .vtu series has the cell field `refinement_level`; `color_by: \"level\"` draws it. "
        "Memory: pre-refinement is counted against `limits.memory` as if it applied to every cell; adaptive "
        "refinement that would pass `limits.memory` stops the run (exit 2).")
      .members({field("criteria", Kind::array).of(criterion_schema()).fallback(nlohmann::json::array())
                    .doc("Refine an element when any criterion wants it; coarsen a family only when all allow it. Empty: only `pre_refine`."),
                field("max_level", Kind::integer).fallback(3).at_least(1).at_most(max_level_index)
                    .doc("Finest level allowed, as an index: 1 is the mesh's own size, each level halves it (3: down to a quarter of the mesh's cell size)."),
                field("pre_refine", Kind::array).of(pre).fallback(nlohmann::json::array()).doc("Regions refined before the run, in order."),
                field("coarsen", Kind::boolean).fallback(false)
                    .doc("Merge a family (8 children, 4 of a quad) back into its parent when the criteria have allowed it for `calm_steps` steps running (momentum kept, the fine-scale kinetic energy dissipated)."),
                field("calm_steps", Kind::integer).fallback(20).at_least(1).at_most(1000000).doc("Hysteresis of coarsening, in steps."),
                field("balance", Kind::boolean).fallback(false)
                    .doc("2:1 balance: before an element is refined, its neighbours (sharing an edge or a face) that would end more than one level coarser are refined first, and coarsening skips families whose merge would break it."),
                field("t_junctions", Kind::string).one_of({"reduction", "paper_projection"}).fallback("reduction")
                    .doc("`reduction`: slave particles with shape-function weights, forces passed to their masters and the reduced system solved (keeps linear and angular momentum); `paper_projection`: the 2014 paper's equal force shares then projection (loses angular momentum).")});
  return r;
}

RefinementSpec read_refinement(const nlohmann::json& j, const Field& schema, const std::string& file) {
  Reader r(j, schema);
  RefinementSpec s;
  s.enabled = true;
  s.max_level = static_cast<std::uint32_t>(r.integer("max_level"));
  s.coarsen = r.boolean("coarsen");
  s.calm_steps = static_cast<std::uint32_t>(r.integer("calm_steps"));
  s.balance = r.boolean("balance");
  s.t_junctions = r.string("t_junctions");
  const Field& cs = *schema.member("criteria")->element_;
  for (std::size_t i = 0; i < r["criteria"].size(); ++i) {
    const nlohmann::json& cj = r["criteria"][i];
    const std::string path = "refinement.criteria[" + std::to_string(i) + "]";
    RefineCriterionSpec c;
    c.type = cj.at("type").get<std::string>();
    Reader cr(cj, cs, c.type);
    if (c.type == "diagonal_strain" || c.type == "strain_energy") c.threshold = cr.number("threshold");
    if (c.type == "region") c.where = geometric_selector(cj.at("where"), *cs.member("where", "region"), file, path + ".where");
    if (c.type == "point") {
      c.point = cr.vec3("point");
      c.radius = cr.number("radius");
    }
    s.criteria.push_back(std::move(c));
  }
  const Field& ps = *schema.member("pre_refine")->element_;
  for (std::size_t i = 0; i < r["pre_refine"].size(); ++i) {
    const nlohmann::json& pj = r["pre_refine"][i];
    const std::string path = "refinement.pre_refine[" + std::to_string(i) + "]";
    Reader pr(pj, ps);
    PreRefineSpec p{geometric_selector(pj.at("where"), *ps.member("where"), file, path + ".where"),
                    static_cast<std::uint32_t>(pr.integer("levels"))};
    if (1 + p.levels > s.max_level)
      throw SceneError(file, path + ".levels",
                       std::to_string(p.levels) + " refinements of the mesh's elements reach level " + std::to_string(1 + p.levels) +
                           ", above refinement.max_level = " + std::to_string(s.max_level));
    s.pre_refine.push_back(p);
  }
  return s;
}

struct RefinementRun::Impl {
  std::string file;
  std::unique_ptr<refine::Criterion<3>> criterion;
  std::unique_ptr<refine::Adapter<3>> adapter;
  refine::RefineOptions options;
  double max_elements = 0;
};

RefinementRun::RefinementRun(const Scene& scene, physics::MssModel<3>& model) : impl_(std::make_unique<Impl>()) {
  const RefinementSpec& spec = scene.refinement;
  impl_->file = scene.file;
  impl_->max_elements = spec.max_elements;
  if (scene.model != "mass-spring")
    throw SceneError(scene.file, "refinement", "refines the mass-spring model only (model.type is \"" + scene.model + "\")");
  if (std::none_of(model.elements().begin(), model.elements().end(), refinable))
    throw SceneError(scene.file, "refinement",
                     "refines hexahedra (1:8) and quads (1:4), and the meshes have none (triangles and tetrahedra are not refined; docs/refinement.md)");
  refine::constrain_t_junctions(model, spec.t_junctions == "paper_projection" ? physics::SlaveTreatment::paper_projection
                                                                              : physics::SlaveTreatment::reduction);
  refine::RefineOptions options;
  options.max_level = static_cast<int>(spec.max_level);
  options.max_elements = static_cast<std::uint64_t>(spec.max_elements);
  options.balance = spec.balance;
  impl_->options = options;
  for (std::size_t i = 0; i < spec.pre_refine.size(); ++i) {
    const PreRefineSpec& p = spec.pre_refine[i];
    const std::string path = "refinement.pre_refine[" + std::to_string(i) + "]";
    const refine::InRegion<3> inside(region_predicate(p.where));
    bool any = false;
    for (physics::Index e = 0; e < model.elements().size() && !any; ++e)
      any = refinable(model.elements()[e]) && inside.wants_refinement(model, e);
    if (!any) throw SceneError(scene.file, path + ".where", "holds the rest centroid of no hexahedron or quad");
    refine::RefineOptions upto = options;
    upto.max_level = static_cast<int>(1 + p.levels);
    for (std::uint32_t pass = 0; pass < p.levels; ++pass) {
      refine::RefineReport rep;
      try {
        rep = refine::adapt(model, inside, upto);
      } catch (const physics::InputError& e) {
        throw SceneError(scene.file, path + ".levels", std::string(e.what()) + " (what limits.memory allows)");
      }
      refined_ += rep.elements;
    }
  }
  if (spec.criteria.empty()) return;
  std::vector<std::unique_ptr<refine::Criterion<3>>> criteria;
  for (std::size_t i = 0; i < spec.criteria.size(); ++i) {
    const RefineCriterionSpec& c = spec.criteria[i];
    if (c.type == "diagonal_strain") criteria.push_back(std::make_unique<refine::DiagonalStrain<3>>(c.threshold));
    if (c.type == "strain_energy") criteria.push_back(std::make_unique<refine::StrainEnergy<3>>(c.threshold));
    if (c.type == "region") criteria.push_back(std::make_unique<refine::InRegion<3>>(region_predicate(c.where)));
    if (c.type == "point") criteria.push_back(std::make_unique<refine::NearPoint<3>>(to_eigen(c.point), c.radius));
    if (c.type == "contact") {
      if (scene.obstacles.empty())
        throw SceneError(scene.file, "refinement.criteria[" + std::to_string(i) + "]", "\"contact\" needs obstacles, and the scene has none");
      std::vector<physics::obstacles::Shape> shapes;
      for (const ObstacleSpec& o : scene.obstacles) shapes.push_back(o.shape);
      criteria.push_back(std::make_unique<refine::InContact<3>>(std::move(shapes)));
    }
  }
  impl_->criterion = std::make_unique<refine::AnyOf<3>>(std::move(criteria));
  refine::Adapter<3>::Options ao;
  ao.refine = options;
  ao.calm_steps = static_cast<int>(spec.calm_steps);
  ao.coarsen = spec.coarsen;
  impl_->adapter = std::make_unique<refine::Adapter<3>>(*impl_->criterion, ao);
}

RefinementRun::~RefinementRun() = default;

bool RefinementRun::after_step(physics::MssModel<3>& model, double t) {
  last_refined_.clear();
  last_coarsened_.clear();
  if (!impl_->adapter) return false;
  refine::Adapter<3>::Report rep;
  try {
    rep = impl_->adapter->update(model);
  } catch (const physics::InputError& e) {
    char when[64];
    std::snprintf(when, sizeof when, " at t = %.6g s", t);
    throw SceneError(impl_->file, "refinement.max_level",
                     std::string(e.what()) + when + " (limits.memory allows about " + count_text(impl_->max_elements) +
                         " hexahedra): lower max_level, raise the criterion's threshold, or raise limits.memory");
  }
  refined_ += rep.refined.elements;
  coarsened_ += rep.coarsened;
  dissipated_ += rep.dissipated_energy;
  last_refined_ = std::move(rep.refined_elements);
  last_coarsened_ = std::move(rep.coarsened_parents);
  return rep.refined.elements > 0 || rep.coarsened > 0;
}

void RefinementRun::redo(physics::MssModel<3>& model, bool coarsening, std::span<const physics::Index> elements) const {
  if (!coarsening) {
    (void)refine::refine_elements(model, elements, impl_->options);
    return;
  }
  for (physics::Index p : elements) (void)refine::coarsen(model, p);  // it refuses what it cannot merge, naming it
}

RefinementRun::State RefinementRun::state() const {
  State s{refined_, coarsened_, dissipated_, {}};
  if (impl_->adapter) s.calm.assign(impl_->adapter->calm_counts().begin(), impl_->adapter->calm_counts().end());
  return s;
}

void RefinementRun::restore(const State& s) {
  refined_ = s.refined;
  coarsened_ = s.coarsened;
  dissipated_ = s.dissipated;
  if (impl_->adapter) impl_->adapter->restore_calm_counts(std::vector<int>(s.calm.begin(), s.calm.end()));
}

}  // namespace sewn::app
