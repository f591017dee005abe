//! SVG
use crate::error::CutError;
use crate::model::{Drawing, Placement};
/// x
#[derive(Clone, Debug)]
pub struct DxfSource;
/// x
pub fn read(_t: &str, _n: &str, _tol: f64) -> Result<(Drawing, DxfSource), CutError> { todo!() }
/// x
pub fn write(_s: &DxfSource, _d: &Drawing, _o: &[Placement]) -> Result<String, CutError> { todo!() }
