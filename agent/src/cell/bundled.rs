//! The ARIAC 2023 cell of `examples/ariac_cell/`, built into btc: the cell
//! `btc trial` uses unless given `--cell`.

use std::path::Path;

/// Where the bundled cell's files say they are (in diagnostics).
pub const CELL_PATH: &str = "examples/ariac_cell/cell.toml";

// Read through `agent/ariac_cell`, a link to `examples/ariac_cell`, so that
// the packaged crate carries the files (`cargo package` follows it).
const FILES: [(&str, &str); 4] = [
    ("cell.toml", include_str!("../../ariac_cell/cell.toml")),
    ("domain.pddl", include_str!("../../ariac_cell/domain.pddl")),
    (
        "floor.btrules",
        include_str!("../../ariac_cell/floor.btrules"),
    ),
    (
        "ceiling.btrules",
        include_str!("../../ariac_cell/ceiling.btrules"),
    ),
];

/// Reads a bundled file by its path under [`CELL_PATH`]'s folder.
pub fn read(path: &Path) -> Result<String, String> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    FILES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| (*t).to_owned())
        .ok_or_else(|| format!("the bundled cell has no file `{name}`"))
}
