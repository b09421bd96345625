//! Any bytes: the parser returns a grid or an error, never panics, and a grid it returns is
//! well formed (leaves on the 8-voxel lattice, tiles of the three tile sizes).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = luxon_volume_vdb::list_grids(data);
    if let Ok(grid) = luxon_volume_vdb::read_grid(data, None) {
        assert!(grid
            .leaves
            .iter()
            .all(|l| l.origin.iter().all(|c| c % 8 == 0)));
        assert!(grid.tiles.iter().all(|t| [8, 128, 4096].contains(&t.size)));
        let _ = grid.index_box();
        let _ = grid.active_voxel_count();
    }
});
