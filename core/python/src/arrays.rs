//! numpy arrays read in place ([`luxon::arrays::Array::external`]): the checks that make it
//! sound (a numpy array of a dtype Luxon reads, in native byte order, rows of the right width
//! with their numbers side by side) and the errors that say what to do otherwise.
//!
//! The array object keeps a reference to the numpy array as the owner of its memory, so the
//! array lives as long as Luxon reads it, whatever Python does with its own names. numpy
//! never moves the data of an array something refers to (`resize` refuses).

use luxon::arrays::{Array, Elem};
use numpy::{PyArrayDescrMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// What an argument holds, each with the dtypes read in place.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Kind {
    /// (n, 3) float32 or float64: positions, normals, colours.
    Vec3,
    /// (n,) float32 or float64: radii.
    Real,
    /// (m, 3) uint32/int32 or uint64/int64: triangles' vertex indices.
    Index3,
    /// (n, 2) float32: texture coordinates.
    Uv,
}

impl Kind {
    /// Numbers per row (`None`: a flat array).
    fn width(self) -> Option<usize> {
        match self {
            Kind::Vec3 | Kind::Index3 => Some(3),
            Kind::Uv => Some(2),
            Kind::Real => None,
        }
    }

    /// The element type of a row of numbers of dtype kind `kind` (b'f', b'u', b'i') and
    /// `size` bytes, if read in place.
    fn elem(self, kind: u8, size: usize) -> Option<Elem> {
        match (self, kind, size) {
            (Kind::Vec3, b'f', 4) => Some(Elem::F32x3),
            (Kind::Vec3, b'f', 8) => Some(Elem::F64x3),
            (Kind::Real, b'f', 4) => Some(Elem::F32),
            (Kind::Real, b'f', 8) => Some(Elem::F64),
            // Signed indices are read as unsigned: a negative one becomes an index past the
            // vertices, which the commit refuses (the package refuses them when added).
            (Kind::Index3, b'u' | b'i', 4) => Some(Elem::U32x3),
            (Kind::Index3, b'u' | b'i', 8) => Some(Elem::U64x3),
            (Kind::Uv, b'f', 4) => Some(Elem::F32x2),
            _ => None,
        }
    }

    fn dtypes(self) -> &'static str {
        match self {
            Kind::Vec3 | Kind::Real => "float32 or float64",
            Kind::Index3 => "uint32, int32, uint64 or int64",
            Kind::Uv => "float32",
        }
    }

    /// The dtype `copy=True` converts to (named in the messages).
    fn convert_to(self) -> &'static str {
        match self {
            Kind::Vec3 | Kind::Real => "np.float64",
            Kind::Index3 => "np.uint32",
            Kind::Uv => "np.float32",
        }
    }

    fn shape(self) -> String {
        match self.width() {
            Some(w) => format!("(n, {w})"),
            None => "(n,)".into(),
        }
    }
}

/// `value` (the argument `what`, e.g. `"spheres: centers"`) as an array Luxon reads in place,
/// and its number of rows. TypeError for anything but a numpy array of a dtype of `kind`;
/// ValueError for a wrong shape or a layout that is not rows of side-by-side numbers.
pub fn borrow(value: &Bound<'_, PyAny>, what: &str, kind: Kind) -> PyResult<(Array, usize)> {
    let name = what.rsplit(": ").next().unwrap_or(what);
    let Ok(a) = value.cast::<PyUntypedArray>() else {
        let ty = value
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_else(|_| "?".into());
        return Err(PyTypeError::new_err(format!(
            "{what}: expected a numpy array of {}, not {ty}; pass copy=True to read other \
             sequences (Luxon keeps a copy), or np.asarray({name}, dtype={})",
            kind.dtypes(),
            kind.convert_to()
        )));
    };
    let dtype = a.dtype();
    let native = dtype.is_native_byteorder().unwrap_or(true);
    let elem = kind
        .elem(dtype.kind(), dtype.itemsize())
        .filter(|_| native && !dtype.has_subarray() && !dtype.has_fields());
    let Some(elem) = elem else {
        let shown = dtype.str().map(|s| s.to_string()).unwrap_or_default();
        let order = if native {
            ""
        } else {
            " in this machine's byte order"
        };
        return Err(PyTypeError::new_err(format!(
            "{what}: an array of dtype {shown}; expected {}{order}. Pass copy=True to have Luxon \
             convert it, or {name}.astype({})",
            kind.dtypes(),
            kind.convert_to()
        )));
    };
    let shape = a.shape();
    let strides = a.strides();
    let shape_ok = match kind.width() {
        Some(w) => shape.len() == 2 && shape[1] == w,
        None => shape.len() == 1,
    };
    if !shape_ok {
        return Err(PyValueError::new_err(format!(
            "{what}: an array of shape {}; expected {}",
            shape_text(shape),
            kind.shape()
        )));
    }
    let n = shape[0];
    let item = dtype.itemsize();
    // The numbers of a row side by side; rows any positive distance apart (a slice of a
    // wider array such as atoms[:, :3] is read in place too).
    let inner_ok = kind.width().is_none_or(|_| strides[1] == item as isize);
    let row_stride = strides[0];
    let rows_ok = n <= 1 || row_stride >= elem.size() as isize;
    if !inner_ok || !rows_ok {
        return Err(PyValueError::new_err(format!(
            "{what}: an array with strides {} bytes (a transposed, reversed or overlapping \
             view) cannot be read in place; pass copy=True, or np.ascontiguousarray({name})",
            shape_text(strides)
        )));
    }
    let stride = if n <= 1 { 0 } else { row_stride as usize };
    // SAFETY: `a` is a numpy array (the cast checked it), whose object struct Python keeps
    // alive while `value` is borrowed.
    let data = unsafe { (*a.as_array_ptr()).fields.data } as *const u8;
    let owner: Py<PyAny> = value.clone().unbind();
    // SAFETY: `data` points at `n` rows of `elem.size()` bytes, `stride` apart (checked above
    // from numpy's shape and strides), inside the array's buffer, which stays where it is
    // while the reference passed as the owner lives (numpy does not move the data of an
    // array that is referred to). numpy memory is readable from any thread. Python code
    // writing the array during a commit or a render breaks the rule the module documents,
    // as it would in C; the reads stay inside the buffer.
    let array = unsafe { Array::external(data, n, stride, elem, owner) }
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    Ok((array, n))
}

fn shape_text<T: std::fmt::Display>(s: &[T]) -> String {
    let parts: Vec<String> = s.iter().map(|d| d.to_string()).collect();
    if parts.len() == 1 {
        format!("({},)", parts[0])
    } else {
        format!("({})", parts.join(", "))
    }
}

/// A ValueError unless `count` rows of `what` match the `n` rows they belong to.
pub fn same_count(what: &str, count: usize, n: usize, of: &str) -> PyResult<()> {
    if count == n {
        return Ok(());
    }
    Err(PyValueError::new_err(format!(
        "{what}: {count} rows for {n} {of}; give one per {}",
        of.trim_end_matches('s')
    )))
}

/// A 3-D numpy array as a volume's voxels, read in place: the array over the memory the
/// view spans, the grid's dims and strides (in elements, x y z) and the element of voxel
/// (0, 0, 0). `order` "zyx": `values[k, j, i]` is voxel (i, j, k) (a C array of slices, as
/// a raw file reads); "xyz": `values[i, j, k]` (nibabel's order). Any strides that are whole
/// elements, negative ones too.
pub fn borrow_grid(value: &Bound<'_, PyAny>, order: &str) -> PyResult<Grid> {
    let what = "volume: values";
    let Ok(a) = value.cast::<PyUntypedArray>() else {
        return Err(PyTypeError::new_err(format!(
            "{what}: expected a numpy array of float32, float64, uint8 or uint16, not {}; pass \
             copy=True, or np.asarray(values, dtype=np.float32)",
            value
                .get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        )));
    };
    let dtype = a.dtype();
    let native = dtype.is_native_byteorder().unwrap_or(true);
    let elem = match (dtype.kind(), dtype.itemsize()) {
        (b'f', 4) => Some(Elem::F32),
        (b'f', 8) => Some(Elem::F64),
        (b'u', 1) => Some(Elem::U8),
        (b'u', 2) => Some(Elem::U16),
        _ => None,
    }
    .filter(|_| native && !dtype.has_subarray() && !dtype.has_fields());
    let Some(elem) = elem else {
        let shown = dtype.str().map(|s| s.to_string()).unwrap_or_default();
        return Err(PyTypeError::new_err(format!(
            "{what}: an array of dtype {shown}; expected float32, float64, uint8 or uint16{}. \
             Pass copy=True to have Luxon convert it, or values.astype(np.float32)",
            if native {
                ""
            } else {
                " in this machine's byte order"
            }
        )));
    };
    let shape = a.shape();
    if shape.len() != 3 || shape.contains(&0) {
        return Err(PyValueError::new_err(format!(
            "{what}: an array of shape {}; expected three dimensions of at least one voxel",
            shape_text(shape)
        )));
    }
    let item = elem.size() as isize;
    let strides = a.strides();
    if strides.iter().any(|s| s % item != 0) {
        return Err(PyValueError::new_err(format!(
            "{what}: strides {} bytes are not whole {}-byte elements; pass copy=True, or \
             np.ascontiguousarray(values)",
            shape_text(strides),
            item
        )));
    }
    // The lowest and highest element the view touches, in elements from voxel (0, 0, 0).
    let (mut low, mut high) = (0isize, 0isize);
    for (d, s) in shape.iter().zip(strides) {
        let reach = (*d as isize - 1) * (s / item);
        if reach < 0 {
            low += reach;
        } else {
            high += reach;
        }
    }
    let (axes, dims) = match order {
        "zyx" => ([2, 1, 0], [shape[2], shape[1], shape[0]]),
        "xyz" => ([0, 1, 2], [shape[0], shape[1], shape[2]]),
        _ => {
            return Err(PyValueError::new_err(format!(
                "volume: order {order:?}; expected \"zyx\" (values[z, y, x]) or \"xyz\""
            )))
        }
    };
    // SAFETY: `a` is a numpy array (the cast checked it), whose object struct Python keeps
    // alive while `value` is borrowed.
    let data = unsafe { (*a.as_array_ptr()).fields.data } as *const u8;
    // The elements from the lowest the view touches to the highest lie in the array's buffer.
    let base = data.wrapping_offset(low * item);
    let len = (high - low + 1) as usize;
    let owner: Py<PyAny> = value.clone().unbind();
    // SAFETY: numpy's shape and strides say every voxel of the view lies in its buffer, so
    // the `len` elements from `base` (the lowest voxel) to the highest one do too, packed
    // (stride 0), and stay there while the owner (a reference to the array) lives; numpy
    // memory is readable from any thread; Luxon copies it into bricks at the commit.
    let values = unsafe { Array::external(base, len, 0, elem, owner) }
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    Ok(Grid {
        values,
        dims: dims.map(|d| d as u64),
        strides: axes.map(|ax| (strides[ax] / item) as i64),
        first: (-low) as u64,
    })
}

/// A volume's voxels as [`borrow_grid`] reads them.
pub struct Grid {
    pub values: Array,
    pub dims: [u64; 3],
    pub strides: [i64; 3],
    pub first: u64,
}
