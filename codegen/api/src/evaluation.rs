//! What an evaluation returns: a matrix, row-major, with its shape.

/// A `rows × cols` matrix, entries row by row (a scalar is 1 × 1, a pose 4 × 4 homogeneous).
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// Row count.
    pub rows: usize,
    /// Column count.
    pub cols: usize,
    /// The `rows · cols` entries, row by row.
    pub data: Vec<f64>,
}

impl Evaluation {
    /// A 1 × 1 matrix.
    pub fn scalar(value: f64) -> Self {
        Evaluation {
            rows: 1,
            cols: 1,
            data: vec![value],
        }
    }

    /// From entries stored column by column (the emitted layout of generated functions).
    pub fn from_column_major(v: &[f64], rows: usize, cols: usize) -> Self {
        let mut data = vec![0.0; rows * cols];
        for c in 0..cols {
            for r in 0..rows {
                data[r * cols + c] = v[c * rows + r];
            }
        }
        Evaluation { rows, cols, data }
    }

    /// From a nalgebra matrix.
    pub fn from_nalgebra<R: nalgebra::Dim, C: nalgebra::Dim, S>(
        m: &nalgebra::Matrix<f64, R, C, S>,
    ) -> Self
    where
        S: nalgebra::RawStorage<f64, R, C>,
    {
        let (rows, cols) = m.shape();
        Evaluation {
            rows,
            cols,
            data: (0..rows)
                .flat_map(|r| (0..cols).map(move |c| (r, c)))
                .map(|(r, c)| m[(r, c)])
                .collect(),
        }
    }

    /// From a faer matrix (the numeric runtime's answers).
    pub fn from_faer(m: &faer::Mat<f64>) -> Self {
        let (rows, cols) = (m.nrows(), m.ncols());
        Evaluation {
            rows,
            cols,
            data: (0..rows)
                .flat_map(|r| (0..cols).map(move |c| (r, c)))
                .map(|(r, c)| m[(r, c)])
                .collect(),
        }
    }

    /// The entry at row `r`, column `c`.
    pub fn get(&self, r: usize, c: usize) -> f64 {
        self.data[r * self.cols + c]
    }

    /// The rows, each a vector.
    pub fn to_rows(&self) -> Vec<Vec<f64>> {
        self.data
            .chunks(self.cols.max(1))
            .take(self.rows)
            .map(<[f64]>::to_vec)
            .collect()
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.data.iter().all(|v| v.is_finite())
    }
}
