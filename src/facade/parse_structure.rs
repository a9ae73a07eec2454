//! What a facade parse found ([`Structure`]): the floors and tiles of its layout, the window
//! of the irreducible tile, the windows found one by one, the frame and sill round them, and
//! the time each stage took. Made by [`parse`](super::parse::parse), written as rules by
//! [`grammar_of`](super::parse_grammar::grammar_of).

use super::rect::Rect;
use super::refinement::Refinement;

/// What the parse found, with the time per stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// Floor height and the rows of the floor splits.
    pub floor: u32,
    /// Floor split rows (first and last bound the repeated floors).
    pub floor_splits: Vec<u32>,
    /// Tile width.
    pub tile: u32,
    /// Tile split columns.
    pub tile_splits: Vec<u32>,
    /// The window within a cell of the final layout (cell pixels).
    pub window: Rect,
    /// First row and column of the cell layout (photo pixels) and its floors × tiles.
    pub origin: (u32, u32),
    /// Floors and tiles of the layout.
    pub count: (usize, usize),
    /// Boundaries of the floors (`count.0 + 1` rows) and of the tiles (`count.1 + 1` columns),
    /// photo pixels: the regular comb moved, floor by floor and column by column, to where
    /// the windows of that floor or column stand out most (Müller's synchronisation).
    pub row_starts: Vec<f64>,
    /// See `row_starts`.
    pub col_starts: Vec<f64>,
    /// Whether each cell (floor-major) holds the repeated tile: cells unlike the irreducible
    /// tile (another building, sky, a shop front) keep plain wall.
    pub present: Vec<bool>,
    /// Repetition strength (relative MI) of the floors and of the tiles.
    pub strength: (f64, f64),
    /// The irreducible tile (mean of the repeated tiles), row-major, `tile × floor`.
    pub irreducible: Vec<f64>,
    /// The windows found one by one ([`super::window_blobs`]), photo pixels.
    pub windows: Vec<Rect>,
    /// Whether the grammar is that of `windows` ([`super::window_grammar`]): when the
    /// layout's windows agree with them less than [`GRID_AGREEMENT`](super::parse::GRID_AGREEMENT); otherwise the grammar
    /// is the layout's (floors and tiles that repeat).
    pub from_windows: bool,
    /// The frame and sill round the grammar's windows ([`super::tile_refinement`]), measured
    /// over all of them (the grammar of windows found one by one measures each size's own).
    pub refinement: Refinement,
    /// Seconds spent in: floor search, tile search, irreducible tile, window (the layout's,
    /// with synchronisation), windows one by one (with the choice of grammar and tile refinement).
    pub seconds: [f64; 5],
}
