//! SVG
use crate::error::CutError;
use crate::model::{Drawing, Placement};
/// x
#[derive(Clone, Debug)]
pub struct GcodeSource;
/// x
pub fn read(_t: &str, _n: &str) -> Result<(Drawing, GcodeSource), CutError> { todo!() }
/// x
pub fn write(_s: &GcodeSource, _d: &Drawing, _o: &[Placement]) -> String { todo!() }
