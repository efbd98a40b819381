//! The `obj_mtl` reader: see `rastergi::fuzzing`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rastergi::fuzzing::Target;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = Target::ObjMtl.read(data) {
        assert!(!e.contains('\n'), "an error of more than one line: {e}");
    }
});
