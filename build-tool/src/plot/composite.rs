//! A grid of pictures with row and column labels and a caption under each: the
//! layout of the paper's Fig. 8 (rows = samplers, columns = samples per pixel).

use super::{err, write_png};
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::Path;

/// One cell: an 8-bit RGB picture (row-major, `3 width height` bytes) and the
/// line written under it.
#[derive(Clone, Debug)]
pub struct Tile<'a> {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// RGB bytes.
    pub rgb: &'a [u8],
    /// Caption (e.g. the RMSE).
    pub caption: String,
}

/// A labelled grid of tiles, `cells[row][column]` (`None`: left empty). All tiles
/// are drawn at the size of the largest.
#[derive(Clone, Debug)]
pub struct Composite<'a> {
    /// Title above the grid.
    pub title: String,
    /// One label per row, left of it.
    pub row_labels: Vec<String>,
    /// One label per column, above it.
    pub column_labels: Vec<String>,
    /// The tiles.
    pub cells: Vec<Vec<Option<Tile<'a>>>>,
}

/// Pixels left of the grid for row labels.
const LABEL_WIDTH: u32 = 150;
/// Pixels above the grid for the title and column labels.
const HEADER: u32 = 52;
/// Pixels under each tile for its caption.
const CAPTION: u32 = 20;
/// Gap between tiles.
const GAP: u32 = 6;

/// Draws `c` and writes it as PNG to `path` atomically. Errors if a tile's buffer
/// does not match its size or the label counts do not match the grid.
pub fn render_composite(path: &Path, c: &Composite<'_>) -> Result<()> {
    let rows = c.cells.len();
    let cols = c.cells.iter().map(Vec::len).max().unwrap_or(0);
    if rows == 0 || cols == 0 || c.row_labels.len() != rows || c.column_labels.len() != cols {
        return Err(anyhow!(
            "composite {}: labels do not match the grid",
            c.title
        ));
    }
    let tiles = c.cells.iter().flatten().flatten();
    let tw = tiles.clone().map(|t| t.width).max().unwrap_or(1);
    let th = tiles.clone().map(|t| t.height).max().unwrap_or(1);
    if let Some(t) = tiles
        .clone()
        .find(|t| t.rgb.len() != (3 * t.width * t.height) as usize)
    {
        return Err(anyhow!(
            "composite {}: tile {} has a wrong buffer",
            c.title,
            t.caption
        ));
    }
    let width = LABEL_WIDTH + cols as u32 * (tw + GAP);
    let height = HEADER + rows as u32 * (th + CAPTION + GAP);
    write_png(path, (width, height), |root| {
        root.draw(&Text::new(c.title.clone(), (8, 6), ("sans-serif", 18)))
            .map_err(err)?;
        for (j, label) in c.column_labels.iter().enumerate() {
            let x = (LABEL_WIDTH + j as u32 * (tw + GAP)) as i32;
            root.draw(&Text::new(label.clone(), (x + 4, 30), ("sans-serif", 15)))
                .map_err(err)?;
        }
        for (i, row) in c.cells.iter().enumerate() {
            let y0 = (HEADER + i as u32 * (th + CAPTION + GAP)) as i32;
            root.draw(&Text::new(
                c.row_labels[i].clone(),
                (6, y0 + th as i32 / 2 - 8),
                ("sans-serif", 15),
            ))
            .map_err(err)?;
            for (j, tile) in row.iter().enumerate() {
                let Some(t) = tile else { continue };
                let x0 = (LABEL_WIDTH + j as u32 * (tw + GAP)) as i32;
                for y in 0..t.height {
                    for x in 0..t.width {
                        let k = (3 * (y * t.width + x)) as usize;
                        let colour = RGBColor(t.rgb[k], t.rgb[k + 1], t.rgb[k + 2]);
                        root.draw_pixel((x0 + x as i32, y0 + y as i32), &colour)
                            .map_err(err)?;
                    }
                }
                root.draw(&Text::new(
                    t.caption.clone(),
                    (x0 + 2, y0 + th as i32 + 2),
                    ("sans-serif", 13),
                ))
                .map_err(err)?;
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_land_in_their_cells_and_bad_grids_are_rejected() {
        let dir = std::env::temp_dir().join(format!("nuld-composite-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let red = [255, 0, 0].repeat(4 * 3);
        let tile = |caption: &str| Tile {
            width: 4,
            height: 3,
            rgb: &red,
            caption: caption.into(),
        };
        let c = Composite {
            title: "t".into(),
            row_labels: vec!["a".into(), "b".into()],
            column_labels: vec!["4".into(), "16".into()],
            cells: vec![vec![Some(tile("x")), None], vec![None, Some(tile("y"))]],
        };
        let path = dir.join("c.png");
        render_composite(&path, &c).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(img.width(), LABEL_WIDTH + 2 * (4 + GAP));
        // The first tile's corner is red, the empty cell beside it white.
        assert_eq!(img.get_pixel(LABEL_WIDTH, HEADER).0, [255, 0, 0]);
        assert_eq!(
            img.get_pixel(LABEL_WIDTH + 4 + GAP, HEADER).0,
            [255, 255, 255]
        );
        let bad = Composite {
            row_labels: vec!["a".into()],
            ..c
        };
        assert!(render_composite(&dir.join("bad.png"), &bad).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
