//! Prints what the reader finds in a .vdb file: `cargo run -p luxon-volume-vdb --example
//! vdb_dump FILE [GRID]`.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: vdb_dump FILE [GRID]");
        std::process::exit(2);
    };
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(1);
        }
    };
    match luxon_volume_vdb::list_grids(&bytes) {
        Ok(list) => {
            for g in list {
                println!("grid `{}`: {}", g.name, g.type_name);
            }
        }
        Err(e) => println!("error: {e}"),
    }
    match luxon_volume_vdb::read_grid(&bytes, args.get(2).map(String::as_str)) {
        Ok(g) => {
            println!(
                "read `{}`: {} half={} class={} map={} bg={} leaves={} tiles={} active={} box={:?}",
                g.name,
                g.value_type,
                g.half,
                g.class,
                g.map,
                g.background,
                g.leaves.len(),
                g.tiles.len(),
                g.active_voxel_count(),
                g.index_box()
            );
            println!("world_from_index {:?}", g.world_from_index);
        }
        Err(e) => println!("error: {e}"),
    }
}
