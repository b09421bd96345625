//! The raw volume reader on arbitrary input: the parameters (RON, as in a scene) up to the
//! first NUL byte, the file's bytes after it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use luxon_plugin::{Error, GridInfo};
use luxon_volume_raw::{read_bytes, Blocks};

/// Checks what the reader hands over instead of storing it.
#[derive(Default)]
struct Count {
    dims: [u64; 3],
    voxels: u64,
}

impl Blocks for Count {
    fn begin(&mut self, info: &GridInfo) -> Result<(), Error> {
        self.dims = info.index_max.map(|m| m as u64 + 1);
        Ok(())
    }

    fn dense(&mut self, _origin: [i64; 3], dims: [u64; 3], values: &[f32]) -> Result<(), Error> {
        assert_eq!(dims.iter().product::<u64>(), values.len() as u64);
        self.voxels += values.len() as u64;
        Ok(())
    }
}

fuzz_target!(|data: &[u8]| {
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let Ok(params) = std::str::from_utf8(&data[..split]) else {
        return;
    };
    let bytes = data.get(split + 1..).unwrap_or(&[]);
    let mut count = Count::default();
    if read_bytes(params, bytes, &mut count).is_ok() {
        assert_eq!(count.voxels, count.dims.iter().product::<u64>());
    }
});
