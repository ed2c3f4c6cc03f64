// Native OMPL on an occupancy grid: the baseline of benchmarks/bench_planners.py.
//
// Reads commands on stdin, one per line, and answers each but `quit` with one line on stdout
// ("error WHY" when it fails):
//   map H W CELLS          CELLS: H*W characters '0' (free) / '1' (obstacle), row-major
//                          (index y * W + x), the grid of the following solves; answers
//                          "mapped H W"
//   solve PLANNER RANGE SX SY GX GY BOUND LIMIT
//                          PLANNER: RRTstar InformedRRTstar BITstar ABITstar AITstar, or
//                          RRTConnect (not an optimizer: it stops at its first solution);
//                          RANGE: the Steer step in pixels (0: OMPL's default);
//                          start and goal (x, y) in pixels; BOUND: the cost threshold at
//                          which the planner stops; LIMIT: seconds
//   flush BYTES            write and read BYTES bytes of a buffer of its own (evicting the
//                          CPU caches the following solve would find warm); answers "flushed"
//   quit
// Answer: "first=S stop=S setup=S cost=C path=X,Y;X,Y;..." with S in seconds since solve()
// began (nan: not reached), setup the seconds spent building space, problem and planner
// (setup() included), cost the final path length (inf: none).
//
// The state space is RealVectorStateSpace(2) on [0, W] x [0, H]; a state is valid when the
// cell floor(x), floor(y) is inside the map and free; motions are checked every 0.5 px
// (OMPL's DiscreteMotionValidator); the objective is path length with the cost threshold
// BOUND; every other setting is OMPL's default. The first argument seeds OMPL's RNG.
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/informedtrees/ABITstar.h>
#include <ompl/geometric/planners/informedtrees/AITstar.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/rrt/InformedRRTstar.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace ob = ompl::base;
namespace og = ompl::geometric;
using Clock = std::chrono::steady_clock;

struct Grid {
    int h = 0, w = 0;
    std::vector<unsigned char> cells;  // 1 = obstacle, index y * w + x
};

class GridChecker : public ob::StateValidityChecker {
  public:
    GridChecker(const ob::SpaceInformationPtr &si, const Grid &g) : ob::StateValidityChecker(si), g_(g) {}
    bool isValid(const ob::State *s) const override {
        const double *v = s->as<ob::RealVectorStateSpace::StateType>()->values;
        if (!(v[0] >= 0.0 && v[1] >= 0.0)) return false;
        const int x = static_cast<int>(v[0]), y = static_cast<int>(v[1]);
        return x < g_.w && y < g_.h && !g_.cells[static_cast<size_t>(y) * g_.w + x];
    }

  private:
    const Grid &g_;
};

static double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The planner named `name` and a getter of its incumbent cost (each class has its own bestCost()).
template <class P>
static ob::PlannerPtr make(const ob::SpaceInformationPtr &si, std::function<double()> &best) {
    auto p = std::make_shared<P>(si);
    P *raw = p.get();
    best = [raw] { return raw->bestCost().value(); };
    return p;
}

static ob::PlannerPtr planner_named(const std::string &name, const ob::SpaceInformationPtr &si,
                                    const ob::ProblemDefinitionPtr &pdef, double range,
                                    std::function<double()> &best) {
    if (name == "RRTConnect") {  // no bestCost(): the length of the solution it has found
        auto p = std::make_shared<og::RRTConnect>(si);
        if (range > 0) p->setRange(range);
        best = [pdef] {
            return pdef->hasExactSolution() ? pdef->getSolutionPath()->length()
                                            : std::numeric_limits<double>::infinity();
        };
        return p;
    }
    if (name == "RRTstar" || name == "InformedRRTstar") {
        auto p = name == "RRTstar" ? make<og::RRTstar>(si, best) : make<og::InformedRRTstar>(si, best);
        if (range > 0) std::static_pointer_cast<og::RRTstar>(p)->setRange(range);
        return p;
    }
    if (range > 0) throw std::invalid_argument(name + " has no range");
    if (name == "BITstar") return make<og::BITstar>(si, best);
    if (name == "ABITstar") return make<og::ABITstar>(si, best);
    if (name == "AITstar") return make<og::AITstar>(si, best);
    throw std::invalid_argument("unknown planner " + name);
}

static std::string solve(const Grid &g, std::istringstream &in) {
    std::string name, tok[7];
    if (!(in >> name >> tok[0] >> tok[1] >> tok[2] >> tok[3] >> tok[4] >> tok[5] >> tok[6]))
        throw std::invalid_argument("solve expects PLANNER RANGE SX SY GX GY BOUND LIMIT");
    double v[7];
    for (int i = 0; i < 7; ++i) v[i] = std::stod(tok[i]);  // stod reads "inf" too
    const double range = v[0], sx = v[1], sy = v[2], gx = v[3], gy = v[4], bound = v[5], limit = v[6];
    if (g.h <= 0) throw std::invalid_argument("no map given before solve");
    const auto t_setup = Clock::now();
    auto space = std::make_shared<ob::RealVectorStateSpace>(2);
    ob::RealVectorBounds box(2);
    box.setLow(0, 0.0), box.setHigh(0, g.w), box.setLow(1, 0.0), box.setHigh(1, g.h);
    space->setBounds(box);
    auto si = std::make_shared<ob::SpaceInformation>(space);
    si->setStateValidityChecker(std::make_shared<GridChecker>(si, g));
    si->setStateValidityCheckingResolution(0.5 / si->getMaximumExtent());
    si->setup();
    ob::ScopedState<> s(space), e(space);
    s[0] = sx, s[1] = sy, e[0] = gx, e[1] = gy;
    auto pdef = std::make_shared<ob::ProblemDefinition>(si);
    pdef->setStartAndGoalStates(s, e, 1e-6);
    auto objective = std::make_shared<ob::PathLengthOptimizationObjective>(si);
    objective->setCostThreshold(ob::Cost(bound));
    pdef->setOptimizationObjective(objective);
    std::function<double()> best;
    auto planner = planner_named(name, si, pdef, range, best);
    planner->setProblemDefinition(pdef);
    planner->setup();
    const double setup = since(t_setup);
    double first = NAN, stop = NAN;
    const auto t0 = Clock::now();
    auto check = [&] {
        const double now = since(t0), c = best();
        if (std::isfinite(c) && std::isnan(first)) first = now;
        if (c <= bound && std::isnan(stop)) stop = now;
        return now >= limit || !std::isnan(stop);
    };
    planner->solve(ob::PlannerTerminationCondition(check));
    check();  // OMPL returns once its cost threshold is met, before asking the condition again
    std::ostringstream out;
    out.precision(17);
    out << "first=" << first << " stop=" << stop << " setup=" << setup;
    if (pdef->hasExactSolution()) {
        auto path = pdef->getSolutionPath()->as<og::PathGeometric>();
        out << " cost=" << path->length() << " path=";
        for (size_t i = 0; i < path->getStateCount(); ++i) {
            const double *v = path->getState(i)->as<ob::RealVectorStateSpace::StateType>()->values;
            out << (i ? ";" : "") << v[0] << "," << v[1];
        }
    } else {
        out << " cost=inf path=";
    }
    return out.str();
}

// Writes and reads `bytes` bytes of a buffer kept for the purpose; the sum keeps the reads.
static std::string flush(std::istringstream &in) {
    static std::vector<unsigned char> buffer;
    long long bytes = -1;
    if (!(in >> bytes) || bytes < 0) throw std::invalid_argument("flush expects BYTES >= 0");
    buffer.resize(static_cast<size_t>(bytes));
    unsigned sum = 0;
    for (size_t i = 0; i < buffer.size(); i += 64) buffer[i] = static_cast<unsigned char>(i);
    for (size_t i = 0; i < buffer.size(); i += 64) sum += buffer[i];
    return "flushed " + std::to_string(sum);
}

static Grid read_map(std::istringstream &in) {
    Grid g;
    std::string cells;
    if (!(in >> g.h >> g.w >> cells) || g.h <= 0 || g.w <= 0 ||
        cells.size() != static_cast<size_t>(g.h) * g.w)
        throw std::invalid_argument("map expects H W and H*W cells");
    g.cells.resize(cells.size());
    for (size_t i = 0; i < cells.size(); ++i) g.cells[i] = cells[i] != '0';
    return g;
}

int main(int argc, char **argv) {
    ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);  // BIT*'s naming notice is a warning
    if (argc > 1) ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(std::stoul(argv[1])));
    Grid grid;
    std::string line;
    while (std::getline(std::cin, line)) {
        std::istringstream in(line);
        std::string cmd;
        in >> cmd;
        try {
            if (cmd == "map") {
                grid = read_map(in);
                std::cout << "mapped " << grid.h << " " << grid.w << std::endl;
            } else if (cmd == "solve") {
                std::cout << solve(grid, in) << std::endl;
            } else if (cmd == "flush") {
                std::cout << flush(in) << std::endl;
            } else if (cmd == "quit") {
                break;
            } else if (!cmd.empty()) {
                throw std::invalid_argument("unknown command " + cmd);
            }
        } catch (const std::exception &err) {
            std::cout << "error " << err.what() << std::endl;
        }
    }
    return 0;
}
