//! Errors of mesh reading and building.

use std::path::PathBuf;

/// What can go wrong when reading or building a mesh. Every variant says what and where.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be opened or read. (The message includes the I/O error, so it is not
    /// also given as the error's source: a reporter printing the chain would repeat it.)
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        error: std::io::Error,
    },
    /// The file's content is not a valid mesh of its format.
    #[error("{format}: {message}")]
    Format {
        /// Which format was being read (`STL`, `OBJ`, `PLY`).
        format: &'static str,
        /// What is wrong, with the line or element where known.
        message: String,
    },
    /// The same, with the file name (the inner error is part of the message, not a source).
    #[error("{path}: {error}")]
    InFile {
        /// The file.
        path: PathBuf,
        /// The error inside it.
        error: Box<MeshError>,
    },
    /// The file extension names no mesh format towpath reads.
    #[error("{path}: unknown mesh format (expected .stl, .obj or .ply)")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// A coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate")]
    NonFinite {
        /// Index of the vertex (in file order).
        index: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {vertex}, but there are only {count} vertices")]
    BadIndex {
        /// Triangle index (file order).
        triangle: usize,
        /// The vertex index it names.
        vertex: usize,
        /// How many vertices there are.
        count: usize,
    },
    /// Nothing is left after removing degenerate triangles.
    #[error("the mesh has no triangle of non-zero area ({read} read, all degenerate)")]
    Empty {
        /// Triangles read.
        read: usize,
    },
    /// The mesh is too large for 32-bit indices.
    #[error("the mesh has {0} vertices or triangles, more than towpath's limit of 2^31")]
    TooLarge(usize),
}

impl MeshError {
    /// Attaches a file name.
    pub fn in_file(self, path: impl Into<PathBuf>) -> MeshError {
        match self {
            e @ (MeshError::Io { .. } | MeshError::InFile { .. } | MeshError::UnknownFormat { .. }) => e,
            e => MeshError::InFile { path: path.into(), error: Box::new(e) },
        }
    }
}
