//! The probabilistic roadmap (Kavraki et al. 1996; thesis Algorithm 14, §5.5 and §6.1).

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

use patch_core::{Point3, Real, UnspecificStepIntersector};
use petgraph::graph::NodeIndex;
use petgraph::unionfind::UnionFind;
use petgraph::visit::Bfs;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::nn::{KdNeighbors, NearestNeighbors};
use crate::planner::{self, Checker, GoalStep, Planner, PlannerStatus, Solution};
use crate::space::{PlanningSpace, Problem};
use crate::termination::Termination;

/// How a new PRM vertex connects to its nearest vertices.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum PrmConnections {
    /// Algorithm 14: the `N` nearest, skipping those already in the vertex's component, so
    /// the roadmap is a forest and paths follow the first connection found.
    Forest,
    /// All of the `N` nearest, also those already in the component, so the roadmap gets
    /// cycles and [`Planner::path_to`] returns the shortest path by length in it (OMPL's PRM
    /// connects this way). Not in the thesis.
    Cycles,
    /// PRM* (Karaman & Frazzoli 2011, the k-nearest variant; not in the thesis): the
    /// `k(n) = ⌈e·(1 + 1/3)·ln n⌉` nearest (3D; [`PrmConfig::neighbours_for`]) instead of
    /// `N`, with cycles.
    Star,
}

/// Which samples become PRM vertices.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum PrmSamples {
    /// Every sample (Algorithm 14, spec §4): a colliding one stays an isolated vertex that
    /// later samples waste neighbour slots on.
    All,
    /// Each sample's sphere is checked first and a colliding one dropped (the iteration still
    /// counts; one capsule check of zero length). OMPL's PRM samples valid states only.
    Valid,
}

/// When the PRM checks its edges.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum PrmEdges {
    /// Each edge when it is added (Algorithm 14).
    Eager,
    /// Only the edges of candidate paths, when a goal is sought (lazy PRM, Bohlin & Kavraki
    /// 2000; [`LazyPrm`]).
    Lazy,
}

/// The choices of a [`Prm`]. No `Default`: pick [`PrmConfig::thesis`] and change fields.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PrmConfig {
    /// How many nearest existing vertices a new sample tries to connect to (the thesis's `N`,
    /// not given there; spec §7.4 recommends at least 6, Fig. 6.9). Ignored with
    /// [`PrmConnections::Star`].
    pub neighbours: usize,
    /// Only vertices within this distance are tried; `None`: no edge-length limit, as in the
    /// thesis (§5.5, §6.1). A non-finite or negative radius connects nothing.
    pub connection_radius: Option<Real>,
    /// Whether each added vertex also tries the straight step to each unreached goal without
    /// a vertex ([`GoalStep::Direct`]: the direct goal test of the thesis's Lesum variants,
    /// §6.2.3, carried over).
    pub goal_step: GoalStep,
    /// How a new vertex connects to its neighbours.
    pub connections: PrmConnections,
    /// Which samples become vertices.
    pub samples: PrmSamples,
    /// When edges are checked.
    pub edges: PrmEdges,
}

impl PrmConfig {
    /// Algorithm 14 as in the thesis: `N = 6` neighbours, no edge-length limit, no direct
    /// goal test.
    pub fn thesis() -> PrmConfig {
        PrmConfig {
            neighbours: 6,
            connection_radius: None,
            goal_step: GoalStep::Grown,
            connections: PrmConnections::Forest,
            samples: PrmSamples::All,
            edges: PrmEdges::Eager,
        }
    }

    /// Algorithm 14 with the two changes a roadmap for path quality wants (not in the
    /// thesis): samples checked before they are added ([`PrmSamples::Valid`]) and edges to
    /// all `N = 6` neighbours ([`PrmConnections::Cycles`]), as OMPL's PRM builds its roadmap.
    pub fn valid() -> PrmConfig {
        PrmConfig {
            samples: PrmSamples::Valid,
            connections: PrmConnections::Cycles,
            ..PrmConfig::thesis()
        }
    }

    /// PRM* (Karaman & Frazzoli 2011, k-nearest variant): [`PrmConnections::Star`], no
    /// edge-length limit, no direct goal test.
    pub fn star() -> PrmConfig {
        PrmConfig { connections: PrmConnections::Star, ..PrmConfig::thesis() }
    }

    /// How many nearest existing vertices a sample tries when it becomes the `vertices`-th
    /// vertex (counting itself and the start): [`neighbours`](Self::neighbours), or with
    /// [`PrmConnections::Star`] `k(n) = ⌈e·(1 + 1/3)·ln n⌉` (0 for `n ≤ 1`).
    pub fn neighbours_for(&self, vertices: usize) -> usize {
        if self.connections != PrmConnections::Star {
            return self.neighbours;
        }
        if vertices <= 1 {
            return 0;
        }
        const DIMENSION: Real = 3.0;
        let k = std::f64::consts::E * (1.0 + 1.0 / DIMENSION) * (vertices as Real).ln();
        k.ceil() as usize
    }
}

/// The PRM (thesis Algorithm 14): a forest of random vertices, components joined by free
/// straight edges.
///
/// The start is vertex 0. Each iteration draws a uniform sample `x`, finds its `N` nearest
/// existing vertices (before adding `x`), adds `x`, and walks those neighbours by increasing
/// distance: it adds the edge if the neighbour is not already in `x`'s component (union–find,
/// the thesis's "associative array node → component", spec §4) and the capsule of the robot
/// radius between them is free. Samples are not checked for validity (spec §4): a colliding
/// sample stays isolated, because every capsule from it includes its sphere. The roadmap is a
/// forest by construction. [`PlanningSpace::max_step`] is not used.
///
/// With [`PrmConnections::Star`] (PRM*, [`PrmConfig::star()`]) `N` grows with the vertex count
/// ([`PrmConfig::neighbours_for`]) and the component test is dropped, so every free edge to
/// the `k(n)` nearest vertices is added and the roadmap has cycles; [`Planner::path_to`]
/// returns the shortest path by length in the roadmap.
///
/// A goal is reached once some vertex within its tolerance is in the start's component.
///
/// Needs only [`UnspecificStepIntersector`] (thesis Table 5.2).
///
/// # Complexity
/// Per iteration a [`KdNeighbors`] query for the neighbours plus at most `N` (PRM*: `k(n)`,
/// `O(log n)`) capsule checks (plus one per goal without a vertex, with the direct goal step).
pub struct Prm<'m, M: UnspecificStepIntersector + ?Sized> {
    map: &'m M,
    space: PlanningSpace,
    config: PrmConfig,
    seed: u64,
    solution: Solution,
}

impl<'m, M: UnspecificStepIntersector + ?Sized> Prm<'m, M> {
    /// A planner on `map` in `space`; `seed` fixes the random stream.
    pub fn new(map: &'m M, space: PlanningSpace, config: PrmConfig, seed: u64) -> Self {
        Prm { map, space, config, seed, solution: Solution::default() }
    }

    /// The lazy PRM (see [`LazyPrm`]) on `map` in `space`: `config` with
    /// [`PrmEdges::Lazy`]; with the same seed its samples are those of [`Prm::new`].
    pub fn lazy(map: &'m M, space: PlanningSpace, config: PrmConfig, seed: u64) -> LazyPrm<'m, M> {
        Prm::new(map, space, PrmConfig { edges: PrmEdges::Lazy, ..config }, seed)
    }

    /// Whether this is the lazy PRM.
    pub fn is_lazy(&self) -> bool {
        self.config.edges == PrmEdges::Lazy
    }

    /// The configuration.
    pub fn config(&self) -> &PrmConfig {
        &self.config
    }

    /// The space.
    pub fn space(&self) -> &PlanningSpace {
        &self.space
    }
}

impl<M: UnspecificStepIntersector + ?Sized> Planner for Prm<'_, M> {
    /// The name of the [`PlannerKind`](crate::PlannerKind) this configuration is, or
    /// `lazy-prm-star`, which has none.
    fn name(&self) -> &'static str {
        use crate::PlannerKind as K;
        let c = &self.config;
        let star = c.connections == PrmConnections::Star;
        let valid = c.samples == PrmSamples::Valid || c.connections == PrmConnections::Cycles;
        match (c.edges, star, valid) {
            (PrmEdges::Eager, false, false) => K::Prm.name(),
            (PrmEdges::Eager, false, true) => K::PrmValid.name(),
            (PrmEdges::Eager, true, _) => K::PrmStar.name(),
            (PrmEdges::Lazy, false, _) => K::LazyPrm.name(),
            (PrmEdges::Lazy, true, _) => "lazy-prm-star",
        }
    }

    fn solve(&mut self, problem: &Problem, stop: &mut dyn Termination) -> PlannerStatus {
        let space = &self.space;
        let sample = |rng: &mut ChaCha8Rng| Some(planner::uniform(rng, space));
        let solution = &mut self.solution;
        solve_prm(self.map, space, &self.config, self.seed, problem, stop, solution, sample)
    }

    planner::solution_accessors!();
}

/// Lazy PRM (Bohlin & Kavraki 2000, "Path planning using lazy PRM"): the PRM's roadmap is
/// built without collision checks, and only the edges of candidate paths are checked; not part
/// of the thesis. A [`Prm`] made by [`Prm::lazy`] (one type, so the eager and the lazy PRM
/// share everything but the edge checks).
///
/// Each iteration draws a uniform sample, adds it, and joins it by *unchecked* edges to its
/// `N` nearest existing vertices ([`PrmConfig::neighbours`]; with [`PrmConnections::Star`] the
/// `k(n)` of PRM*), within [`PrmConfig::connection_radius`]. There is no component test:
/// unchecked edges are optimistic, and a forest of them would lose a connection for good when
/// one of its edges turns out to collide (Bohlin & Kavraki likewise connect to all
/// neighbours). Every edge is Unknown, Free or Colliding; a result, once checked, is kept.
///
/// # Queries and goal detection
/// After each iteration, for every unreached goal, the query of Bohlin & Kavraki runs: the
/// shortest path (Dijkstra by length) from the start to any vertex within the goal's tolerance
/// over the edges not known to collide; all its Unknown edges are checked, the colliding ones
/// are deleted and the search repeats, until a path whose edges are all Free is found (the goal
/// is reached by its last vertex) or none is left. Checking the whole path rather than stopping
/// at its first colliding edge (Bohlin & Kavraki's order) spends a few checks on edges a later
/// path may not use, but deletes several colliding edges per search: on the office benchmark it
/// makes the lazy PRM 15 times faster (3.8 s → 0.26 s per run), because each search and
/// union–find rebuild costs `O(E log V)`.
///
/// Batching: a query round that deleted edges and still left a goal unreached is not
/// repeated before the roadmap has grown by a tenth (every new edge would otherwise trigger a
/// new search over a graph whose walls are still full of optimistic edges, a quadratic cost).
/// Goals are then detected at most a tenth of the vertices later than with a query after
/// every iteration.
///
/// Soundness: a goal counts as reached only through edges checked free. The union–find of the
/// eager PRM is kept, but over the *optimistic* graph (all edges not known to collide) and only
/// as a filter: the query runs only when it joins the start with a vertex near the goal. Since
/// deleting an edge may split a component, which a union–find cannot undo, it is rebuilt from
/// the remaining edges after a query that deleted edges. So after a failed query the filter is
/// exact again, and the query is repeated only once new edges join the start's optimistic
/// component to the goal again.
///
/// The direct goal step ([`PrmConfig::goal_step`]) stays eager: its capsule is checked
/// at once, as in the [`Prm`].
///
/// [`Planner::roadmap`] holds every vertex but only the edges checked free (the roadmap's
/// contract: an edge is a motion found free), so [`PlannerCounters::edges`](crate::PlannerCounters::edges) counts those;
/// [`Planner::path_to`] returns the shortest path over them.
///
/// Needs only [`UnspecificStepIntersector`].
///
/// # Complexity
/// Per iteration a [`KdNeighbors`] query; per query round a Dijkstra search over the
/// optimistic graph (`O(E log V)`) per deleted edge, at most one capsule check per Unknown
/// edge of the path found, and a union–find rebuild (`O(E α(V))`) when an edge is deleted;
/// failed rounds happen at most once per tenth of growth. Every edge is checked at most once.
pub type LazyPrm<'m, M> = Prm<'m, M>;

/// The PRM's working state besides the roadmap.
struct Forest {
    nn: KdNeighbors,
    components: UnionFind<usize>,
    /// Per goal, the vertices within its tolerance.
    near_goal: Vec<Vec<NodeIndex>>,
    /// Per goal, whether its centre is a vertex.
    goal_vertex: Vec<bool>,
    /// The unchecked edges of the lazy PRM (`None`: the eager PRM). With it, `components` is
    /// the union–find of the optimistic graph.
    lazy: Option<LazyEdges>,
}

impl Forest {
    fn add(&mut self, solution: &mut Solution, p: Point3) -> NodeIndex {
        let v = solution.graph.add_node(p);
        self.nn.add(p);
        self.components.new_set();
        if let Some(lazy) = &mut self.lazy {
            lazy.adjacency.push(Vec::new());
        }
        for (g, goal) in solution.goals.iter().enumerate() {
            if (goal.center - p).norm() <= goal.tolerance {
                self.near_goal[g].push(v);
            }
        }
        v
    }

    /// Adds the edge `a`–`b`, found free, to the roadmap (and, lazily, as a Free edge).
    fn connect(&mut self, solution: &mut Solution, a: NodeIndex, b: NodeIndex) {
        let length = (solution.graph[a] - solution.graph[b]).norm();
        solution.graph.add_edge(a, b, length);
        self.components.union(a.index(), b.index());
        if let Some(lazy) = &mut self.lazy {
            lazy.push(a, b, length, EdgeState::Free);
        }
    }

    /// Adds the unchecked edge `a`–`b` to the lazy graph.
    fn connect_lazily(&mut self, solution: &Solution, a: NodeIndex, b: NodeIndex) {
        let length = (solution.graph[a] - solution.graph[b]).norm();
        let lazy = self.lazy.as_mut().expect("lazy mode");
        lazy.push(a, b, length, EdgeState::Unknown);
        self.components.union(a.index(), b.index());
    }
}

/// What is known of a lazy edge.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum EdgeState {
    Unknown,
    Free,
    Colliding,
}

/// An edge of the lazy PRM's optimistic graph.
struct LazyEdge {
    a: NodeIndex,
    b: NodeIndex,
    length: Real,
    state: EdgeState,
}

/// The lazy PRM's graph: all edges with what is known of them.
#[derive(Default)]
struct LazyEdges {
    edges: Vec<LazyEdge>,
    /// Per vertex, the ids of its edges.
    adjacency: Vec<Vec<usize>>,
    /// Whether an edge was deleted since the union–find was built.
    stale: bool,
    /// Edges found colliding so far.
    deletions: usize,
    /// Queries wait until the roadmap has this many vertices (see [`LazyPrm`]'s batching).
    next_query: usize,
}

impl LazyEdges {
    fn push(&mut self, a: NodeIndex, b: NodeIndex, length: Real, state: EdgeState) {
        let id = self.edges.len();
        self.edges.push(LazyEdge { a, b, length, state });
        self.adjacency[a.index()].push(id);
        self.adjacency[b.index()].push(id);
    }

    /// The union–find of the edges not known to collide.
    fn components(&self) -> UnionFind<usize> {
        let mut uf = UnionFind::new(self.adjacency.len());
        for e in self.edges.iter().filter(|e| e.state != EdgeState::Colliding) {
            uf.union(e.a.index(), e.b.index());
        }
        uf
    }

    /// The edge ids of a shortest path (by length) from `from` to the first target reached,
    /// over the edges not known to collide (Dijkstra; ties by vertex index), and that target.
    fn shortest_path(
        &self,
        from: NodeIndex,
        targets: &[NodeIndex],
    ) -> Option<(Vec<usize>, NodeIndex)> {
        let n = self.adjacency.len();
        let mut is_target = vec![false; n];
        for t in targets {
            is_target[t.index()] = true;
        }
        let mut dist = vec![Real::INFINITY; n];
        let mut via: Vec<Option<usize>> = vec![None; n];
        let mut heap = BinaryHeap::new();
        dist[from.index()] = 0.0;
        heap.push(Queued { cost: 0.0, vertex: from.index() });
        while let Some(Queued { cost, vertex }) = heap.pop() {
            if cost > dist[vertex] {
                continue;
            }
            if is_target[vertex] {
                let mut path = Vec::new();
                let mut v = vertex;
                while let Some(id) = via[v] {
                    path.push(id);
                    let e = &self.edges[id];
                    v = if e.a.index() == v { e.b.index() } else { e.a.index() };
                }
                path.reverse();
                return Some((path, NodeIndex::new(vertex)));
            }
            for &id in &self.adjacency[vertex] {
                let e = &self.edges[id];
                if e.state == EdgeState::Colliding {
                    continue;
                }
                let w = if e.a.index() == vertex { e.b.index() } else { e.a.index() };
                let d = cost + e.length;
                if d < dist[w] {
                    dist[w] = d;
                    via[w] = Some(id);
                    heap.push(Queued { cost: d, vertex: w });
                }
            }
        }
        None
    }
}

/// A vertex in Dijkstra's queue; the heap pops the lowest cost first (ties: lower index).
#[derive(Copy, Clone, Debug)]
struct Queued {
    cost: Real,
    vertex: usize,
}

impl PartialEq for Queued {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Queued {}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        other.cost.total_cmp(&self.cost).then(other.vertex.cmp(&self.vertex))
    }
}

/// The PRM loop shared by [`Prm`], [`LazyPrm`] ([`PrmEdges::Lazy`]) and the MA PRM: `sample(rng)` gives
/// the next vertex, or `None` to drop the iteration's sample (it still counts as an
/// iteration).
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_prm<M: UnspecificStepIntersector + ?Sized>(
    map: &M,
    space: &PlanningSpace,
    config: &PrmConfig,
    seed: u64,
    problem: &Problem,
    stop: &mut dyn Termination,
    solution: &mut Solution,
    mut sample: impl FnMut(&mut ChaCha8Rng) -> Option<Point3>,
) -> PlannerStatus {
    let started = Instant::now();
    let lazy = config.edges == PrmEdges::Lazy;
    solution.reset(&problem.goals);
    let mut checker = Checker::new(map, space.robot_radius());
    if let Some(invalid) = planner::validate(problem, space, &mut checker) {
        solution.finish(0, &checker);
        return invalid;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let goals = problem.goals.len();
    let mut forest = Forest {
        nn: KdNeighbors::new(),
        components: UnionFind::new(0),
        near_goal: vec![Vec::new(); goals],
        goal_vertex: vec![false; goals],
        lazy: lazy.then(LazyEdges::default),
    };
    let max_dist = match config.connection_radius {
        None => Real::INFINITY,
        Some(r) if r.is_finite() && r >= 0.0 => r,
        Some(_) => Real::NEG_INFINITY,
    };
    let start = forest.add(solution, problem.start);
    direct_goal_steps(solution, &mut forest, &mut checker, config, start);
    update_reached(solution, &mut forest, &mut checker);
    let mut iterations = 0u64;
    while !stop.should_stop(&solution.progress(iterations, started)) {
        iterations += 1;
        let Some(x) = sample(&mut rng) else {
            continue;
        };
        if config.samples == PrmSamples::Valid && !checker.free(&x, &x) {
            continue;
        }
        let k = config.neighbours_for(solution.graph.node_count() + 1);
        let near = forest.nn.k_nearest(&x, k, max_dist);
        let v = forest.add(solution, x);
        for n in near {
            let w = NodeIndex::new(n.index);
            if lazy {
                forest.connect_lazily(solution, w, v);
            } else if (config.connections != PrmConnections::Forest
                || !forest.components.equiv(v.index(), w.index()))
                && checker.free(&solution.graph[w], &x)
            {
                forest.connect(solution, w, v);
            }
        }
        direct_goal_steps(solution, &mut forest, &mut checker, config, v);
        update_reached(solution, &mut forest, &mut checker);
    }
    solution.finish(iterations, &checker);
    if lazy {
        // Connected to the start through edges checked free: the roadmap's own edges.
        let mut connected = vec![false; solution.graph.node_count()];
        let mut bfs = Bfs::new(&solution.graph, start);
        while let Some(v) = bfs.next(&solution.graph) {
            connected[v.index()] = true;
        }
        return solution.status(|v| connected[v.index()]);
    }
    let start_root = forest.components.find(start.index());
    solution.status(|v| forest.components.find(v.index()) == start_root)
}

/// With the direct goal step: connects `v` to the centre of each unreached goal that has no
/// vertex yet, if the capsule is free.
fn direct_goal_steps<M: UnspecificStepIntersector + ?Sized>(
    solution: &mut Solution,
    forest: &mut Forest,
    checker: &mut Checker<'_, M>,
    config: &PrmConfig,
    v: NodeIndex,
) {
    if config.goal_step == GoalStep::Grown {
        return;
    }
    for g in 0..solution.goals.len() {
        if solution.reached[g].is_some() || forest.goal_vertex[g] {
            continue;
        }
        let center = solution.goals[g].center;
        if checker.free(&solution.graph[v], &center) {
            let w = forest.add(solution, center);
            forest.connect(solution, v, w);
            forest.goal_vertex[g] = true;
        }
    }
}

/// Marks goals whose nearby vertices joined the start's component (lazily: for which a query
/// finds a path of edges checked free).
fn update_reached<M: UnspecificStepIntersector + ?Sized>(
    solution: &mut Solution,
    forest: &mut Forest,
    checker: &mut Checker<'_, M>,
) {
    let n = solution.graph.node_count();
    let deletions_before = match &forest.lazy {
        Some(lazy) if n < lazy.next_query => return,
        Some(lazy) => Some(lazy.deletions),
        None => None,
    };
    for g in 0..solution.goals.len() {
        if solution.reached[g].is_some() {
            continue;
        }
        if forest.lazy.is_some() {
            solution.reached[g] = lazy_query(solution, forest, checker, g);
        } else {
            solution.reached[g] =
                forest.near_goal[g].iter().copied().find(|w| forest.components.equiv(0, w.index()));
        }
    }
    // Batching: a query round that deleted edges and still left a goal unreached waits for
    // the roadmap to grow by a tenth before the next one.
    if let (Some(lazy), Some(before)) = (&mut forest.lazy, deletions_before)
        && lazy.deletions > before
        && solution.reached.iter().any(Option::is_none)
    {
        lazy.next_query = n + n / 10 + 1;
    }
}

/// The query of the lazy PRM for goal `g` (see [`LazyPrm`]): the vertex near the goal at the
/// end of a path from the start whose edges are all checked free, or `None`.
fn lazy_query<M: UnspecificStepIntersector + ?Sized>(
    solution: &mut Solution,
    forest: &mut Forest,
    checker: &mut Checker<'_, M>,
    g: usize,
) -> Option<NodeIndex> {
    let start = NodeIndex::new(0);
    loop {
        let lazy = forest.lazy.as_mut().expect("lazy mode");
        if lazy.stale {
            forest.components = lazy.components();
            lazy.stale = false;
        }
        if !forest.near_goal[g].iter().any(|w| forest.components.equiv(0, w.index())) {
            return None;
        }
        let (path, target) = lazy.shortest_path(start, &forest.near_goal[g])?;
        let mut all_free = true;
        for id in path {
            let edge = &mut lazy.edges[id];
            if edge.state != EdgeState::Unknown {
                continue;
            }
            let (a, b) = (edge.a, edge.b);
            if checker.free(&solution.graph[a], &solution.graph[b]) {
                edge.state = EdgeState::Free;
                solution.graph.add_edge(a, b, edge.length);
            } else {
                edge.state = EdgeState::Colliding;
                lazy.stale = true;
                lazy.deletions += 1;
                all_free = false;
            }
        }
        if all_free {
            return Some(target);
        }
    }
}
