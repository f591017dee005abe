//! Fuzzes the cut DXF reader: no input may make it panic, and an accepted drawing must
//! order, write and read back with the same number of pieces.
#![no_main]

use libfuzzer_sys::fuzz_target;
use towpath_cut::io::{read, write, Format};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let format = Format::Dxf;
    let Ok((drawing, source)) = read(format, &text, "fuzz", 1e-3) else { return };
    let placements = towpath_cut::model::as_drawn(&drawing);
    let Ok(out) = write(&source, &drawing, &placements) else { return };
    if let Ok((back, _)) = read(format, &out, "again", 1e-3) {
        assert_eq!(back.pieces.len(), drawing.pieces.len(), "write/read changed the number of pieces");
    }
});
