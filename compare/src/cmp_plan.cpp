// cmp_plan: OMPL's RRT, RRTConnect and PRM for a sphere robot in R^3 among the triangles of an
// OBJ mesh, collision checked with FCL; reads a planning problem JSON of the shared exchange
// format and prints one JSON line per run in its results schema (kind "planning").
//
//   cmp_plan PROBLEM.json --planner rrt|rrtconnect|prm --mode explore|solve|roi
//            [--seed S] [--iterations K] [--time-limit SEC] [--goal-bias P] [--prm-k K] [--direct-goal]
//
// --direct-goal (RRT, PRM) gives OMPL the project's goal test: after each new vertex, the goal is
// reached when the vertex is within the tolerance or the capsule from it to the goal centre is
// free (RRT: a GoalState subclass, goal bias 0 as the project's RRT; PRM: an edge to the goal
// milestone). Without it OMPL runs as shipped (RRT goal bias 0.05, GoalState threshold).
//
// The budget of every mode is the problem's `iterations` (or --iterations): explore runs exactly
// K iterations; solve and roi stop when the goal(s) are reached or after K iterations in total.
// State validity: in bounds and fcl::Sphere(r) free of the mesh's BVH (OBBRSS). Motion validity:
// fcl::Capsule(r, |b - a|) around the segment a-b free (the exact swept sphere, as the project
// checks it). Every run is a forked child, so ompl::RNG::setSeed applies to it alone.

#include <sys/wait.h>
#include <unistd.h>

#include <iostream>
#include <memory>

#include <Eigen/Geometry>
#include <fcl/config.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBBRSS.h>
#include <fcl/narrowphase/collision.h>
#include <nlohmann/json.hpp>
#include <ompl/base/MotionValidator.h>
#include <ompl/base/PlannerData.h>
#include <ompl/base/OptimizationObjective.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateValidityChecker.h>
#include <ompl/base/goals/GoalState.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/terminationconditions/IterationTerminationCondition.h>
#include <ompl/config.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include "io.hpp"

namespace ob = ompl::base;
namespace og = ompl::geometric;
using json = nlohmann::json;
using Bvh = fcl::BVHModel<fcl::OBBRSSd>;

#define CMP_STR2(x) #x
#define CMP_STR(x) CMP_STR2(x)
static const char *TOOL = "ompl-" CMP_STR(OMPL_MAJOR_VERSION) "." CMP_STR(OMPL_MINOR_VERSION) "." CMP_STR(
    OMPL_PATCH_VERSION) "+fcl-" FCL_VERSION;

// ------------------------------------------------------------------ FCL checks
struct Checker {
  std::shared_ptr<Bvh> bvh;
  double r = 0;
  unsigned long spheres = 0, capsules = 0;

  bool sphere_free(const Eigen::Vector3d &p) {
    ++spheres;
    fcl::Sphered s(r);
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.translation() = p;
    fcl::CollisionRequestd req;
    fcl::CollisionResultd res;
    fcl::collide(&s, tf, bvh.get(), fcl::Transform3d::Identity(), req, res);
    return !res.isCollision();
  }
  bool capsule_free(const Eigen::Vector3d &a, const Eigen::Vector3d &b) {
    const Eigen::Vector3d d = b - a;
    const double len = d.norm();
    if (len < 1e-12) return sphere_free(a);
    ++capsules;
    fcl::Capsuled c(r, len);
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d / len).toRotationMatrix();
    tf.translation() = 0.5 * (a + b);
    fcl::CollisionRequestd req;
    fcl::CollisionResultd res;
    fcl::collide(&c, tf, bvh.get(), fcl::Transform3d::Identity(), req, res);
    return !res.isCollision();
  }
};

static Eigen::Vector3d at(const ob::State *s) {
  const auto *v = s->as<ob::RealVectorStateSpace::StateType>();
  return {v->values[0], v->values[1], v->values[2]};
}

static void put(ob::State *s, const Eigen::Vector3d &p) {
  auto *v = s->as<ob::RealVectorStateSpace::StateType>();
  for (int i = 0; i < 3; ++i) v->values[i] = p[i];
}

class SphereValidity : public ob::StateValidityChecker {
 public:
  SphereValidity(const ob::SpaceInformationPtr &si, Checker &c) : ob::StateValidityChecker(si), c_(c) {}
  bool isValid(const ob::State *s) const override { return si_->satisfiesBounds(s) && c_.sphere_free(at(s)); }

 private:
  Checker &c_;
};

class CapsuleMotion : public ob::MotionValidator {
 public:
  CapsuleMotion(const ob::SpaceInformationPtr &si, Checker &c) : ob::MotionValidator(si), c_(c) {}
  bool checkMotion(const ob::State *a, const ob::State *b) const override {
    const bool ok = si_->satisfiesBounds(b) && c_.capsule_free(at(a), at(b));
    ok ? ++valid_ : ++invalid_;
    return ok;
  }
  // Needed by some planners only (not RRT, RRTConnect or PRM): the last free point by bisection.
  bool checkMotion(const ob::State *a, const ob::State *b, std::pair<ob::State *, double> &last) const override {
    if (checkMotion(a, b)) return true;
    const Eigen::Vector3d pa = at(a), pb = at(b);
    double lo = 0, hi = 1;
    while ((hi - lo) * (pb - pa).norm() > 1e-3) {
      const double mid = 0.5 * (lo + hi);
      (c_.capsule_free(pa, pa + mid * (pb - pa)) ? lo : hi) = mid;
    }
    if (last.first != nullptr) si_->getStateSpace()->interpolate(a, b, lo, last.first);
    last.second = lo;
    return false;
  }

 private:
  Checker &c_;
};

/// Explore mode: a goal nothing satisfies and that is never sampled.
class NoGoal : public ob::Goal {
 public:
  using ob::Goal::Goal;
  bool isSatisfied(const ob::State *) const override { return false; }
};

/// The project's goal test (`--direct-goal`): a vertex reaches the goal when it lies within the
/// tolerance of the goal centre, or when the capsule from it to the centre is free. Added as a
/// goal region through OMPL's public Goal interface; RRT calls it once per new vertex.
class DirectGoal : public ob::GoalState {
 public:
  DirectGoal(const ob::SpaceInformationPtr &si, Checker &c) : ob::GoalState(si), c_(c) {}
  bool isSatisfied(const ob::State *s, double *distance) const override {
    const double d = si_->distance(s, state_);
    if (distance != nullptr) *distance = d;
    return d <= threshold_ || c_.capsule_free(at(s), at(state_));
  }

 private:
  Checker &c_;
};

/// OMPL's PRM (its roadmap, k-nearest connection strategy, motion checks and A* solution),
/// driven one uniform sample per iteration so that an iteration means what it means in the
/// project's PRM: one sample drawn, added as a milestone when valid.
class CountedPrm : public og::PRM {
 public:
  using og::PRM::PRM;

  /// Adds start and goal milestones, then samples until every goal shares the start's
  /// component or `budget` iterations are done; returns the iterations done.
  unsigned long run(const Eigen::Vector3d &start, const std::vector<Eigen::Vector3d> &goals, unsigned long budget,
                    double time_limit, bool direct, Checker &chk, std::vector<double> &lengths) {
    auto space = si_->getStateSpace();
    ob::State *s = si_->allocState();
    put(s, start);
    Vertex vs = addMilestone(si_->cloneState(s));
    std::vector<Vertex> vg;
    for (const auto &g : goals) {
      put(s, g);
      vg.push_back(addMilestone(si_->cloneState(s)));
    }
    auto sampler = si_->allocStateSampler();
    const auto t0 = cmp::Clock::now();
    unsigned long it = 0;
    auto all_connected = [&] {
      for (Vertex g : vg)
        if (!sameComponent(vs, g)) return false;
      return true;
    };
    while (it < budget && !(goals.size() > 0 && all_connected()) && cmp::since(t0) < time_limit) {
      ++it;
      sampler->sampleUniform(s);
      if (!si_->isValid(s)) continue;
      const Vertex m = addMilestone(si_->cloneState(s));
      if (!direct) continue;
      // the project's direct goal step: the new milestone straight to every goal not yet in its component
      for (size_t k = 0; k < vg.size(); ++k) {
        if (sameComponent(m, vg[k]) || !chk.capsule_free(at(s), goals[k])) continue;
        const Graph::edge_property_type w(opt_->motionCost(stateProperty_[m], stateProperty_[vg[k]]));
        boost::add_edge(m, vg[k], w, g_);
        uniteComponents(m, vg[k]);
      }
    }
    si_->freeState(s);
    lengths.clear();
    for (Vertex g : vg) {
      if (!sameComponent(vs, g)) {
        lengths.push_back(-1);
        continue;
      }
      auto path = constructSolution(vs, g);
      lengths.push_back(path->as<og::PathGeometric>()->length());
    }
    return it;
  }
};

// ------------------------------------------------------------------ problem
struct Problem {
  std::string name, mesh;
  double r = 0, step = 0, tol = 0;
  Eigen::Vector3d lo, hi, start;
  std::vector<Eigen::Vector3d> goals;
  long iterations = 1000;
  std::vector<long> seeds;
};

static Eigen::Vector3d v3(const json &j) {
  Eigen::Vector3d v(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>());
  if (!v.allFinite()) throw std::runtime_error("non-finite coordinate in the problem");
  return v;
}

static Problem load(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  const json j = json::parse(in);
  Problem p;
  p.name = j.value("name", cmp::stem(path));
  p.mesh = j.at("mesh").get<std::string>();
  if (p.mesh.empty() || p.mesh[0] != '/') p.mesh = cmp::parent(path) + "/" + p.mesh;
  p.r = j.at("robot_radius").get<double>();
  p.step = j.at("max_step").get<double>();
  p.tol = j.value("goal_tolerance", 0.0);
  p.lo = v3(j.at("bounds").at("min"));
  p.hi = v3(j.at("bounds").at("max"));
  p.start = v3(j.at("start"));
  for (const auto &g : j.at("goals")) p.goals.push_back(v3(g));
  p.iterations = j.value("iterations", 1000L);
  for (const auto &s : j.value("seeds", json::array())) p.seeds.push_back(s.get<long>());
  if (p.seeds.empty()) p.seeds.push_back(0);
  if (!(p.r > 0 && p.step > 0 && p.tol >= 0 && (p.hi - p.lo).minCoeff() > 0 && p.iterations > 0))
    throw std::runtime_error("robot_radius, max_step, bounds or iterations out of range");
  return p;
}

struct Options {
  std::string problem, planner = "rrt", mode = "solve";
  long seed = -1, iterations = -1;
  double time_limit = 60, goal_bias = 0.05;
  unsigned prm_k = 6;
  bool direct_goal = false;
};

// ------------------------------------------------------------------ one run
static json run(const Problem &p, const Options &o, long seed, Checker &chk) {
  ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(seed + 1));  // OMPL takes 0 as "pick one"
  const unsigned long K = static_cast<unsigned long>(o.iterations > 0 ? o.iterations : p.iterations);
  auto space = std::make_shared<ob::RealVectorStateSpace>(3);
  ob::RealVectorBounds b(3);
  for (int i = 0; i < 3; ++i) b.setLow(i, p.lo[i]), b.setHigh(i, p.hi[i]);
  space->setBounds(b);
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker(std::make_shared<SphereValidity>(si, chk));
  si->setMotionValidator(std::make_shared<CapsuleMotion>(si, chk));
  si->setup();

  const std::string pname = o.planner == "rrt" ? "RRT" : o.planner == "prm" ? "PRM" : "RRTConnect";
  json row = {{"kind", "planning"}, {"tool", TOOL}, {"planner", pname}, {"backend", "fcl-obbrss"},
              {"map", cmp::stem(p.mesh) + ".obj"}, {"problem", p.name}, {"mode", o.mode}, {"seed", seed},
              {"motion", "capsule"}, {"budget_iterations", K}, {"direct_goal", o.direct_goal}};
  ob::ScopedState<> start(space);
  put(start.get(), p.start);
  if (!si->isValid(start.get())) {
    row["skipped"] = "the start is in collision or out of bounds";
    return row;
  }
  chk.spheres = chk.capsules = 0;

  std::vector<Eigen::Vector3d> goals;
  if (o.mode != "explore") goals = p.goals;
  std::vector<double> lengths(goals.size(), -1);
  unsigned long iterations = 0, vertices = 0;
  double time_s = 0;

  if (o.planner == "prm") {
    auto prm = std::make_shared<CountedPrm>(si);
    prm->setMaxNearestNeighbors(o.prm_k);
    auto pdef = std::make_shared<ob::ProblemDefinition>(si);
    pdef->addStartState(start);
    pdef->setGoal(std::make_shared<NoGoal>(si));
    prm->setProblemDefinition(pdef);
    prm->setup();
    const auto t0 = cmp::Clock::now();
    iterations = prm->run(p.start, goals, K, o.time_limit, o.direct_goal, chk, lengths);
    time_s = cmp::since(t0);
    vertices = prm->milestoneCount();
  } else {
    ob::PlannerPtr pl;
    if (o.planner == "rrt") {
      auto rrt = std::make_shared<og::RRT>(si);
      rrt->setRange(p.step);
      rrt->setGoalBias(o.direct_goal ? 0.0 : o.goal_bias);  // the project's RRT: uniform samples
      pl = rrt;
    } else {
      if (o.mode == "explore") throw std::runtime_error("RRTConnect has no explore mode (it needs a goal tree)");
      auto c = std::make_shared<og::RRTConnect>(si);
      c->setRange(p.step);
      pl = c;
    }
    auto pdef = std::make_shared<ob::ProblemDefinition>(si);
    pdef->addStartState(start);
    auto vertex_count = [&] {
      ob::PlannerData pd(si);
      pl->getPlannerData(pd);
      return static_cast<unsigned long>(pd.numVertices());
    };
    if (o.mode == "explore") {
      pdef->setGoal(std::make_shared<NoGoal>(si));
      pl->setProblemDefinition(pdef);
      pl->setup();
      ob::IterationTerminationCondition itc(static_cast<unsigned>(K));
      const auto t0 = cmp::Clock::now();
      pl->solve(ob::plannerOrTerminationCondition(itc, ob::timedPlannerTerminationCondition(o.time_limit)));
      time_s = cmp::since(t0);
      iterations = std::min<unsigned long>(itc.getTimesCalled(), K);
      vertices = vertex_count();
    } else {
      // The goals in turn from one tree (RRT keeps its tree across solve calls; RRTConnect
      // cannot keep its goal tree and starts afresh), sharing one budget of K iterations.
      for (size_t g = 0; g < goals.size() && iterations < K; ++g) {
        auto goal = o.direct_goal && o.planner == "rrt" ? std::make_shared<DirectGoal>(si, chk)
                                                        : std::make_shared<ob::GoalState>(si);
        ob::ScopedState<> gs(space);
        put(gs.get(), goals[g]);
        goal->setState(gs);
        goal->setThreshold(p.tol);
        if (g > 0 && o.planner == "rrtconnect") pl->clear();
        pdef->clearSolutionPaths();
        pdef->setGoal(goal);
        if (g == 0) {
          pl->setProblemDefinition(pdef);
          pl->setup();
        } else if (o.planner == "rrtconnect") {
          pl->setProblemDefinition(pdef);
        }
        ob::IterationTerminationCondition itc(static_cast<unsigned>(K - iterations));
        const auto t0 = cmp::Clock::now();
        const ob::PlannerStatus st = pl->solve(
            ob::plannerOrTerminationCondition(itc, ob::timedPlannerTerminationCondition(o.time_limit - time_s)));
        time_s += cmp::since(t0);
        iterations += std::min<unsigned long>(itc.getTimesCalled(), K - iterations);
        if (st == ob::PlannerStatus::EXACT_SOLUTION) {
          auto *path = pdef->getSolutionPath()->as<og::PathGeometric>();
          lengths[g] = path->length();
          // reached by the direct step: the path goes on to the goal centre
          const Eigen::Vector3d last = at(path->getStates().back());
          if ((last - goals[g]).norm() > p.tol) lengths[g] += (last - goals[g]).norm();
        }
        vertices = o.planner == "rrtconnect" ? vertices + vertex_count() : vertex_count();
        if (lengths[g] < 0) break;
      }
    }
  }
  bool solved = !goals.empty();
  double total = 0;
  json per_goal = json::array();
  for (double l : lengths) {
    solved = solved && l >= 0;
    total += std::max(l, 0.0);
    per_goal.push_back({{"solved", l >= 0}, {"path_length", l >= 0 ? json(l) : json(nullptr)}});
  }
  row["iterations"] = iterations;
  row["vertices"] = vertices;
  row["time_s"] = time_s;
  row["collision_checks"] = chk.spheres + chk.capsules;
  row["state_checks"] = chk.spheres;
  row["solved"] = solved;
  row["path_length"] = solved ? json(total) : json(nullptr);
  if (o.mode == "roi") row["goals"] = per_goal;
  return row;
}

static void usage() {
  std::cerr << "usage: cmp_plan PROBLEM.json --planner rrt|rrtconnect|prm --mode explore|solve|roi\n"
               "                [--seed S] [--iterations K] [--time-limit SEC] [--goal-bias P] [--prm-k K]\n"
               "                [--direct-goal]   (RRT, PRM: the project's goal test, RRT without goal bias)\n"
               "  solve: one run per goal (start -> goal); roi: all goals from one tree / roadmap\n";
}

static int real_main(int argc, char **argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--planner") o.planner = next();
    else if (a == "--mode") o.mode = next();
    else if (a == "--seed") o.seed = std::stol(next());
    else if (a == "--iterations") o.iterations = std::stol(next());
    else if (a == "--time-limit") o.time_limit = std::stod(next());
    else if (a == "--goal-bias") o.goal_bias = std::stod(next());
    else if (a == "--prm-k") o.prm_k = static_cast<unsigned>(std::stoul(next()));
    else if (a == "--direct-goal") o.direct_goal = true;
    else if (a == "-h" || a == "--help") { usage(); return 0; }
    else if (!a.empty() && a[0] == '-') { usage(); return 2; }
    else o.problem = a;
  }
  if (o.problem.empty() || (o.planner != "rrt" && o.planner != "rrtconnect" && o.planner != "prm") ||
      (o.mode != "explore" && o.mode != "solve" && o.mode != "roi") || !(o.time_limit > 0) ||
      !(o.goal_bias >= 0 && o.goal_bias <= 1) || o.prm_k == 0) {
    usage();
    return 2;
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
  const Problem p = load(o.problem);
  const cmp::Mesh m = cmp::read_obj(p.mesh);
  Checker chk;
  chk.r = p.r;
  chk.bvh = std::make_shared<Bvh>();
  {
    std::vector<fcl::Vector3d> v;
    std::vector<fcl::Triangle> t;
    for (const auto &x : m.vertices) v.emplace_back(x[0], x[1], x[2]);
    for (const auto &f : m.triangles) t.emplace_back(f[0], f[1], f[2]);
    chk.bvh->beginModel(static_cast<int>(t.size()), static_cast<int>(v.size()));
    chk.bvh->addSubModel(v, t);
    chk.bvh->endModel();
    chk.bvh->computeLocalAABB();
  }
  const std::vector<long> seeds = o.seed >= 0 ? std::vector<long>{o.seed} : p.seeds;
  // solve: one run per (seed, goal) with that goal alone; explore/roi: one run per seed
  std::vector<std::pair<long, int>> runs;
  for (long s : seeds) {
    if (o.mode == "solve")
      for (int g = 0; g < static_cast<int>(p.goals.size()); ++g) runs.emplace_back(s, g);
    else
      runs.emplace_back(s, -1);
  }
  int failures = 0;
  for (const auto &[seed, goal] : runs) {
    std::cout.flush();
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid == 0) {
      try {
        Problem q = p;
        if (goal >= 0) q.goals = {p.goals[goal]};
        json row = run(q, o, seed, chk);
        if (goal >= 0) row["goal"] = goal;
        std::cout << row.dump() << std::endl;
        _exit(0);
      } catch (const std::exception &e) {
        std::cerr << "cmp_plan: seed " << seed << ": " << e.what() << "\n";
        _exit(1);
      }
    }
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) ++failures;
  }
  return failures == 0 ? 0 : 1;
}

int main(int argc, char **argv) {
  try {
    return real_main(argc, argv);
  } catch (const std::exception &e) {
    std::cerr << "cmp_plan: " << e.what() << "\n";
    return 1;
  }
}
