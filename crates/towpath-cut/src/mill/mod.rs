//! 2.5D machining after Castelino, D'Souza & Wright (2003): pocket features offset per tool
//! into contour-parallel toolpath cells ([`cells`]), the cells of each tool linked into one
//! toolpath from the origin and back under the feature hierarchy ([`link`]), written as G-code
//! and drawn ([`output`]); the part description is read by [`part`].

pub mod cells;
pub mod link;
pub mod output;
pub mod part;

pub use cells::{cell_path, cells_for_tool, offset_levels, Cell, CellPath, Region};
pub use link::{check_plan, plan, MillOptions, Plan, ToolPlan};
pub use part::{read_part, Feature, Part, Tool};
