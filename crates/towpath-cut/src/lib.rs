//! # towpath-cut: cutting, plotting and 2.5D machining
//!
//! Laser, waterjet, plasma and plotter jobs: closed contours and open strokes are ordered with
//! the least rapid (pen-up) travel, each contour entered at its best point, strokes reversed
//! where allowed, and every piece inside a closed contour done before it (holes before the part,
//! parts before the sheet around them). And the machining job of Castelino, D'Souza & Wright
//! (2003): pocket features offset into contour-parallel toolpath cells per tool, the cells linked
//! from the origin and back under the feature hierarchy.
//!
//! - [`geom`]: paths of lines, arcs and cubics with exact reversal and restart.
//! - [`model`]: [`Drawing`], [`Piece`], [`Placement`].
//! - [`contain`]: containment precedence. [`lead`]: lead-ins on the scrap side.
//! - [`order`](mod@order): the ordering problem on `towpath_seq`, entry refinement.
//! - [`stroke_search`]: the local search for stroke tours (2-opt, Or-opt, kicks) the ordering uses.
//! - [`verify`](mod@verify): the independent verifier of an ordering.
//! - [`io`]: readers and writers (SVG, DXF, G-code, JSON).
//! - [`mill`]: pocket offsetting into toolpath cells, linking per tool, G-code and drawings.

#![warn(missing_docs)]

pub mod contain;
pub mod error;
pub mod geom;
pub mod greedy_match;
pub mod io;
pub mod lead;
pub mod mill;
pub mod model;
pub mod order;
pub mod point_grid;
pub mod stroke_search;
pub mod verify;

pub use error::CutError;
pub use geom::{Path, Place, Seg, P2};
pub use model::{Drawing, Piece, Placement};
pub use order::{order, EntryMode, OrderOptions, OrderReport};
pub use verify::{verify, Verification};
