//! `render!`: the one way a figure reaches its file (SVG or PNG by the extension), with every
//! failure naming the file. Declared first in `plot`, so every figure module can use it.

/// Draws `$body` (which sees the drawing area as `$root` and whether the target is SVG as
/// `$svg`, and returns this crate's `Result<()>`) on a PNG or SVG backend chosen by the extension
/// of `$path`, then writes the file; every failure is an `Error::Draw` or `Error::UnknownFormat`
/// naming the file. Returns from the enclosing function on failure, else evaluates to `Ok(())`.
macro_rules! render {
    ($path:expr, $size:expr, |$root:ident, $svg:ident| $body:expr) => {{
        let path: &std::path::Path = $path;
        let draw = |message: String| $crate::error::Error::Draw {
            file: path.to_path_buf(),
            message,
        };
        match $crate::plot::format::Format::from_path(path) {
            Some(format) => {
                $crate::plot::fonts::register();
                let $svg = format == $crate::plot::format::Format::Svg;
                if $svg {
                    let $root = $crate::plot::fonts::Glyphs(plotters::prelude::SVGBackend::new(
                        path, $size,
                    ))
                    .into_drawing_area();
                    $body.map_err(|e: $crate::error::Error| draw(e.chain_text()))?;
                    $root.present().map_err(|e| draw(e.to_string()))?;
                } else {
                    let $root = $crate::plot::fonts::Glyphs(plotters::prelude::BitMapBackend::new(
                        path, $size,
                    ))
                    .into_drawing_area();
                    $body.map_err(|e: $crate::error::Error| draw(e.chain_text()))?;
                    $root.present().map_err(|e| draw(e.to_string()))?;
                }
            }
            None => {
                return Err($crate::error::Error::UnknownFormat {
                    file: path.to_path_buf(),
                    message: "unknown file type; use .svg or .png",
                });
            }
        }
        Ok(())
    }};
}
