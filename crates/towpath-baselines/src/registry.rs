//! The solver registry: names, parameters and one entry point for every solver.

use std::fmt;
use std::str::FromStr;

use towpath_seq::{CostModel, Problem, SolveError, SolveOptions, SolveReport, Violation};

use crate::{solve_aco, solve_castelino, solve_doherty, solve_ga, AcoParams, CastelinoParams, DohertyParams, GaParams};

/// The solvers `--solver NAME` can select.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum SolverName {
    /// towpath's own solver (`towpath_seq::solve`): the default.
    #[default]
    Towpath,
    /// Doherty et al. (2022) §3.2: seed pool + nearest neighbour, depth-first and breadth-first search.
    Doherty,
    /// Castelino et al. (2003): GTSP → ATSP (2n) transformation, solved by towpath's SOP/TSP search.
    Castelino,
    /// Tewolde & Sheng (2008) §IV: the genetic algorithm.
    Ga,
    /// Tewolde & Sheng (2008) §V: the ant system with one ant per required edge.
    Aco1,
    /// Tewolde & Sheng (2008) §V: the ant system with two ants per required edge (one at each end).
    #[cfg_attr(feature = "clap", value(alias = "aco"))]
    Aco2,
}

impl SolverName {
    /// Every solver, towpath first.
    pub const ALL: [SolverName; 6] = [
        SolverName::Towpath,
        SolverName::Doherty,
        SolverName::Castelino,
        SolverName::Ga,
        SolverName::Aco1,
        SolverName::Aco2,
    ];

    /// The name as typed on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            SolverName::Towpath => "towpath",
            SolverName::Doherty => "doherty",
            SolverName::Castelino => "castelino",
            SolverName::Ga => "ga",
            SolverName::Aco1 => "aco1",
            SolverName::Aco2 => "aco2",
        }
    }

    /// True for the solvers whose answer depends on `SolveOptions::seed`.
    pub fn is_randomized(self) -> bool {
        matches!(
            self,
            SolverName::Towpath | SolverName::Castelino | SolverName::Ga | SolverName::Aco1 | SolverName::Aco2
        )
    }

    /// Where the algorithm comes from.
    pub fn reference(self) -> &'static str {
        match self {
            SolverName::Towpath => "towpath's own solver",
            SolverName::Doherty => "Doherty et al. 2022, §3.2",
            SolverName::Castelino => "Castelino et al. 2003, §5",
            SolverName::Ga => "Tewolde & Sheng 2008, §IV",
            SolverName::Aco1 | SolverName::Aco2 => "Tewolde & Sheng 2008, §V",
        }
    }
}

impl fmt::Display for SolverName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// An unknown solver name.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown solver {0:?}: choose one of towpath, doherty, castelino, ga, aco1, aco2 (aco = aco2)")]
pub struct UnknownSolver(pub String);

impl FromStr for SolverName {
    type Err = UnknownSolver;
    /// Parses a solver name (case-insensitive); `aco` means `aco2`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let l = s.trim().to_ascii_lowercase();
        if l == "aco" {
            return Ok(SolverName::Aco2);
        }
        SolverName::ALL.into_iter().find(|n| n.as_str() == l).ok_or_else(|| UnknownSolver(s.to_string()))
    }
}

/// The parameters of every baseline; each solver reads its own part.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BaselineParams {
    /// Doherty et al.'s (2022) solver.
    pub doherty: DohertyParams,
    /// Castelino et al.'s (2003) transformation.
    pub castelino: CastelinoParams,
    /// Tewolde & Sheng's (2008) GA.
    pub ga: GaParams,
    /// Tewolde & Sheng's (2008) ant system; `ants_per_task` is set by the choice of `aco1` or `aco2`.
    pub aco: AcoParams,
}

/// Why a solver failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BaselineError {
    /// towpath's solver (directly, or inside `castelino`) failed.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// The initial route given in the options is not feasible.
    #[error("the initial route is not feasible: {0}")]
    BadInitial(Violation),
    /// The solver found no feasible route.
    #[error("no feasible route found: {0}")]
    NoFeasibleRoute(Violation),
    /// The problem has a feature the solver's paper does not handle.
    #[error("{solver} cannot solve this problem: {reason}")]
    Unsupported {
        /// The solver.
        solver: SolverName,
        /// What it cannot handle.
        reason: String,
    },
    /// The problem is too large for the solver's data structures.
    #[error("{solver}: the problem is too large: {what}")]
    TooLarge {
        /// The solver.
        solver: SolverName,
        /// What is too large.
        what: String,
    },
    /// The precedence sets given to `doherty` do not fit the problem.
    #[error("doherty: bad precedence sets: {0}")]
    BadSets(String),
    /// A parameter is out of range.
    #[error("bad parameter: {0}")]
    BadParams(String),
    /// A parameter asks for more memory or work than the solver takes on.
    #[error("{message}")]
    TooMuch {
        /// The parameter, as a field path of [`BaselineParams`] (`ga.population`).
        param: &'static str,
        /// What it would take and what is allowed.
        message: String,
    },
}

/// Solves `problem` with the named solver.
pub fn solve_with<C: CostModel>(
    name: SolverName,
    problem: &Problem<C>,
    opts: &SolveOptions,
    params: &BaselineParams,
) -> Result<SolveReport, BaselineError> {
    match name {
        SolverName::Towpath => Ok(towpath_seq::solve(problem, opts)?),
        SolverName::Doherty => solve_doherty(problem, &params.doherty, opts),
        SolverName::Castelino => solve_castelino(problem, &params.castelino, opts),
        SolverName::Ga => solve_ga(problem, &params.ga, opts),
        SolverName::Aco1 => solve_aco(problem, &AcoParams { ants_per_task: 1, ..params.aco.clone() }, opts),
        SolverName::Aco2 => solve_aco(problem, &AcoParams { ants_per_task: 2, ..params.aco.clone() }, opts),
    }
    .map_err(|e| match (name, e) {
        (n, BaselineError::TooLarge { what, .. }) => BaselineError::TooLarge { solver: n, what },
        (_, e) => e,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for n in SolverName::ALL {
            assert_eq!(n.as_str().parse::<SolverName>().unwrap(), n);
            assert_eq!(n.to_string().to_uppercase().parse::<SolverName>().unwrap(), n);
        }
        assert_eq!("aco".parse::<SolverName>().unwrap(), SolverName::Aco2);
        let e = "lkh".parse::<SolverName>().unwrap_err();
        assert!(e.to_string().contains("towpath, doherty"));
    }
}
