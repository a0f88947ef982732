//! The streaming binary STL reader with tiny chunks and forced join runs, against `stl::parse` of the
//! same bytes (see stl_stream_check.rs).
#![no_main]

#[path = "stl_stream_check.rs"]
mod stl_stream_check;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(e) = stl_stream_check::check(data) {
        panic!("{e}");
    }
});
