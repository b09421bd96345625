//! `luxon._luxon.Scene`: a retained scene ([`luxon::api::Scene`]) edited through RON text,
//! its lights and objects named by id tokens. `luxon.Scene` (python/luxon/_scene.py) subclasses
//! it with keyword arguments and the handles users see.

use crate::arrays::{borrow, borrow_grid, same_count, Kind};
use crate::context::PyContext;
use crate::errors::{guard, IntoPy};
use luxon::api::{
    self, Cylinders, LightId, MaterialId, Mesh, ObjectId, Radius, Renderer, RendererOptions,
    Spheres, VolumeGrid,
};
use luxon::arrays::Array;
use numpy::{PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

#[pyclass(module = "luxon._luxon", name = "Scene", subclass)]
pub struct PyScene {
    pub(crate) context: Py<PyContext>,
    pub(crate) scene: api::Scene,
    /// Renderers by thread count (`None`: the context's pool), made on first use.
    renderers: Vec<(Option<usize>, Arc<Renderer>)>,
    /// The arrays of each array object, to mark modified.
    arrays: HashMap<ObjectId, Vec<Array>>,
}

/// Radii: one number for all, or an (n,) array read in place (kept in `held`).
fn radius(
    value: &Bound<'_, PyAny>,
    what: &str,
    n: usize,
    of: &str,
    held: &mut Vec<Array>,
) -> PyResult<Radius> {
    let array = value.cast::<PyUntypedArray>().is_ok_and(|a| a.ndim() > 0);
    if !array {
        if let Ok(r) = value.extract::<f64>() {
            return Ok(Radius::Const(r));
        }
    }
    let (a, k) = borrow(value, what, Kind::Real)?;
    same_count(what, k, n, of)?;
    held.push(a.clone());
    Ok(Radius::Each(a))
}

/// A light's id in its scene (compared and hashed; `luxon.Light` holds one).
#[pyclass(module = "luxon._luxon", name = "LightId", frozen, eq, hash)]
#[derive(PartialEq, Eq, Hash)]
pub struct PyLightId(pub LightId);

/// An object's id in its scene (compared and hashed; `luxon.Object` holds one).
#[pyclass(module = "luxon._luxon", name = "ObjectId", frozen, eq, hash)]
#[derive(PartialEq, Eq, Hash)]
pub struct PyObjectId(pub ObjectId);

#[pymethods]
impl PyLightId {
    fn __repr__(&self) -> String {
        format!("<{}>", self.0)
    }
}

#[pymethods]
impl PyObjectId {
    fn __repr__(&self) -> String {
        format!("<{}>", self.0)
    }
}

#[pymethods]
impl PyScene {
    /// An empty scene, or with `_path` the scene file loaded (any format Luxon reads).
    #[new]
    #[pyo3(signature = (context, _path = None))]
    fn new(py: Python<'_>, context: Py<PyContext>, _path: Option<PathBuf>) -> PyResult<Self> {
        guard(|| {
            let ctx = context.get().ctx.clone();
            let scene = match _path {
                Some(path) => py.detach(|| api::Scene::load(&ctx, &path)).py_err()?,
                None => api::Scene::new(&ctx),
            };
            Ok(PyScene {
                context,
                scene,
                renderers: Vec::new(),
                arrays: HashMap::new(),
            })
        })
    }

    /// The context the scene was made with.
    #[getter]
    fn context(&self, py: Python<'_>) -> Py<PyContext> {
        self.context.clone_ref(py)
    }

    fn _set_camera_ron(&mut self, text: &str) -> PyResult<()> {
        guard(|| self.scene.set_camera_ron(text).py_err())
    }

    fn _set_render_ron(&mut self, text: &str) -> PyResult<()> {
        guard(|| self.scene.set_render_ron(text).py_err())
    }

    fn _set_background(&mut self, rgb: [f64; 3]) -> PyResult<()> {
        guard(|| self.scene.set_background(rgb).py_err())
    }

    fn _set_origin(&mut self, world: Option<[f64; 3]>) -> PyResult<()> {
        guard(|| self.scene.set_origin(world).py_err())
    }

    /// `None` clears the fog.
    fn _set_fog_ron(&mut self, text: Option<&str>) -> PyResult<()> {
        guard(|| match text {
            Some(t) => self.scene.set_fog_ron(t).py_err(),
            None => self.scene.set_fog(None).py_err(),
        })
    }

    /// `None` turns ambient occlusion off.
    fn _set_ambient_occlusion_ron(&mut self, text: Option<&str>) -> PyResult<()> {
        guard(|| match text {
            Some(t) => self.scene.set_ambient_occlusion_ron(t).py_err(),
            None => self.scene.set_ambient_occlusion(None).py_err(),
        })
    }

    fn _add_light_ron(&mut self, text: &str) -> PyResult<PyLightId> {
        guard(|| self.scene.add_light_ron(text).py_err().map(PyLightId))
    }

    fn _set_light_ron(&mut self, id: &PyLightId, text: &str) -> PyResult<()> {
        guard(|| self.scene.set_light_ron(id.0, text).py_err())
    }

    fn _remove_light(&mut self, id: &PyLightId) -> PyResult<()> {
        guard(|| self.scene.remove_light(id.0).py_err())
    }

    fn _lights(&self) -> Vec<PyLightId> {
        self.scene.lights().into_iter().map(PyLightId).collect()
    }

    fn _set_material_ron(&mut self, name: &str, text: &str) -> PyResult<()> {
        guard(|| self.scene.set_material_ron(name, text).py_err().map(|_| ()))
    }

    fn _set_texture(&mut self, name: &str, plugin: &str, params: &str) -> PyResult<()> {
        guard(|| self.scene.set_texture(name, plugin, params).py_err())
    }

    fn _set_clip_group_ron(&mut self, name: &str, text: &str) -> PyResult<()> {
        guard(|| self.scene.set_clip_group_ron(name, text).py_err().map(drop))
    }

    fn _has_clip_group(&self, name: &str) -> bool {
        self.scene.clip_group(name).is_some()
    }

    #[pyo3(signature = (plugin, params, name = None, look = None))]
    fn _add_plugin_volume(
        &mut self,
        plugin: &str,
        params: &str,
        name: Option<&str>,
        look: Option<&str>,
    ) -> PyResult<PyObjectId> {
        guard(|| {
            let id = match look {
                Some(look) => self.scene.add_plugin_volume_ron(plugin, params, name, look),
                None => self.scene.add_plugin_volume(plugin, params, name, None),
            };
            Ok(PyObjectId(id.py_err()?))
        })
    }

    fn _has_material(&self, name: &str) -> bool {
        self.scene.material(name).is_some()
    }

    #[pyo3(signature = (plugin, params, material = None, clip = None))]
    fn _add_plugin_object(
        &mut self,
        plugin: &str,
        params: &str,
        material: Option<&str>,
        clip: Option<&str>,
    ) -> PyResult<PyObjectId> {
        guard(|| {
            let material = self.material_id(material)?;
            let clip = match clip {
                None => None,
                Some(name) => Some(self.scene.clip_group(name).ok_or_else(|| {
                    PyValueError::new_err(format!("no clip group named `{name}` in this scene"))
                })?),
            };
            let id = self
                .scene
                .add_plugin_object(plugin, params, material, clip)
                .py_err()?;
            Ok(PyObjectId(id))
        })
    }

    fn _remove_object(&mut self, id: &PyObjectId) -> PyResult<()> {
        guard(|| {
            self.scene.remove(id.0).py_err()?;
            self.arrays.remove(&id.0);
            Ok(())
        })
    }

    /// Spheres read from numpy arrays: `radii` a number or an (n,) array.
    #[pyo3(signature = (centers, radii, colors = None, material = None, id = None))]
    fn _spheres(
        &mut self,
        centers: &Bound<'_, PyAny>,
        radii: &Bound<'_, PyAny>,
        colors: Option<&Bound<'_, PyAny>>,
        material: Option<&str>,
        id: Option<&PyObjectId>,
    ) -> PyResult<PyObjectId> {
        guard(|| {
            let (centers, n) = borrow(centers, "spheres: centers", Kind::Vec3)?;
            let mut held = vec![centers.clone()];
            let radius = radius(radii, "spheres: radii", n, "centers", &mut held)?;
            let mut s = Spheres::new(centers, radius);
            if let Some(c) = colors {
                let (c, k) = borrow(c, "spheres: colors", Kind::Vec3)?;
                same_count("spheres: colors", k, n, "centers")?;
                held.push(c.clone());
                s.colors = Some(c);
            }
            s.material = self.material_id(material)?;
            let id = match id {
                Some(id) => self.scene.set_spheres(id.0, s).py_err().map(|_| id.0)?,
                None => self.scene.add_spheres(s).py_err()?,
            };
            self.arrays.insert(id, held);
            Ok(PyObjectId(id))
        })
    }

    /// Cylinders read from numpy arrays: `radii` a number or an (n,) array.
    #[pyo3(signature = (bases, apexes, radii, caps = true, material = None, id = None))]
    fn _cylinders(
        &mut self,
        bases: &Bound<'_, PyAny>,
        apexes: &Bound<'_, PyAny>,
        radii: &Bound<'_, PyAny>,
        caps: bool,
        material: Option<&str>,
        id: Option<&PyObjectId>,
    ) -> PyResult<PyObjectId> {
        guard(|| {
            let (bases, n) = borrow(bases, "cylinders: a", Kind::Vec3)?;
            let (apexes, k) = borrow(apexes, "cylinders: b", Kind::Vec3)?;
            same_count("cylinders: b", k, n, "bases (a)")?;
            let mut held = vec![bases.clone(), apexes.clone()];
            let radius = radius(radii, "cylinders: radii", n, "cylinders", &mut held)?;
            let mut c = Cylinders::new(bases, apexes, radius);
            c.caps = caps;
            c.material = self.material_id(material)?;
            let id = match id {
                Some(id) => self.scene.set_cylinders(id.0, c).py_err().map(|_| id.0)?,
                None => self.scene.add_cylinders(c).py_err()?,
            };
            self.arrays.insert(id, held);
            Ok(PyObjectId(id))
        })
    }

    /// A triangle mesh read from numpy arrays (`indices` None: every three vertices).
    #[pyo3(signature = (vertices, indices = None, normals = None, colors = None, uvs = None, material = None, id = None))]
    #[allow(clippy::too_many_arguments)]
    fn _mesh(
        &mut self,
        vertices: &Bound<'_, PyAny>,
        indices: Option<&Bound<'_, PyAny>>,
        normals: Option<&Bound<'_, PyAny>>,
        colors: Option<&Bound<'_, PyAny>>,
        uvs: Option<&Bound<'_, PyAny>>,
        material: Option<&str>,
        id: Option<&PyObjectId>,
    ) -> PyResult<PyObjectId> {
        guard(|| {
            let (positions, n) = borrow(vertices, "mesh: vertices", Kind::Vec3)?;
            if indices.is_none() && n % 3 != 0 {
                return Err(PyValueError::new_err(format!(
                    "mesh: {n} vertices without indices; a triangle soup needs a multiple of \
                     three (or give indices of shape (m, 3))"
                )));
            }
            let mut held = vec![positions.clone()];
            let mut per_vertex = |a: Option<&Bound<'_, PyAny>>, what: &str, kind: Kind| {
                a.map(|a| {
                    let (a, k) = borrow(a, what, kind)?;
                    same_count(what, k, n, "vertices")?;
                    held.push(a.clone());
                    Ok::<_, PyErr>(a)
                })
                .transpose()
            };
            let normals = per_vertex(normals, "mesh: normals", Kind::Vec3)?;
            let colors = per_vertex(colors, "mesh: colors", Kind::Vec3)?;
            let uvs = per_vertex(uvs, "mesh: uvs", Kind::Uv)?;
            let indices = indices
                .map(|i| borrow(i, "mesh: indices", Kind::Index3).map(|(a, _)| a))
                .transpose()?;
            held.extend(indices.clone());
            let m = Mesh {
                positions,
                indices,
                normals,
                colors,
                uvs,
                material: self.material_id(material)?,
            };
            let id = match id {
                Some(id) => self.scene.set_mesh(id.0, m).py_err().map(|_| id.0)?,
                None => self.scene.add_mesh(m).py_err()?,
            };
            self.arrays.insert(id, held);
            Ok(PyObjectId(id))
        })
    }

    /// A volume from a 3-D numpy array (see `luxon.Scene.volume`), drawn as `look` (RON).
    #[pyo3(signature = (values, order, origin, spacing, normalize, name, look, id = None))]
    #[allow(clippy::too_many_arguments)]
    fn _volume(
        &mut self,
        values: &Bound<'_, PyAny>,
        order: &str,
        origin: [f64; 3],
        spacing: [f64; 3],
        normalize: bool,
        name: Option<String>,
        look: &str,
        id: Option<&PyObjectId>,
    ) -> PyResult<PyObjectId> {
        guard(|| {
            let g = borrow_grid(values, order)?;
            let grid = VolumeGrid {
                values: g.values.clone(),
                dims: g.dims,
                strides: Some(g.strides),
                first: g.first,
                origin,
                spacing,
                normalize,
                name: name.unwrap_or_default(),
            };
            let id = match id {
                Some(id) => self
                    .scene
                    .set_volume_ron(id.0, grid, look)
                    .py_err()
                    .map(|_| id.0)?,
                None => self.scene.add_volume_ron(grid, look).py_err()?,
            };
            self.arrays.insert(id, vec![g.values]);
            Ok(PyObjectId(id))
        })
    }

    /// Marks every array of object `id` modified: the next commit reads them again.
    fn _modified(&self, id: &PyObjectId) -> PyResult<()> {
        match self.arrays.get(&id.0) {
            Some(arrays) => {
                arrays.iter().for_each(Array::mark_modified);
                Ok(())
            }
            None if !self.scene.objects().contains(&id.0) => Err(crate::errors::to_py(
                api::Error::Api(format!("{} was removed from this scene", id.0)),
            )),
            None => Err(PyValueError::new_err(format!(
                "{} is made by a plugin, not read from arrays",
                id.0
            ))),
        }
    }

    fn _objects(&self) -> Vec<PyObjectId> {
        self.scene.objects().into_iter().map(PyObjectId).collect()
    }

    fn _to_ron(&self) -> PyResult<String> {
        guard(|| self.scene.to_ron().py_err())
    }

    /// The render settings' sample count now.
    fn _samples(&self) -> u32 {
        self.scene.desc().render.samples
    }

    /// Brings the built scene up to date; what it did as a dict.
    fn _commit<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(|| {
            let renderer = self.renderer(None)?;
            let scene = &mut self.scene;
            let r = py.detach(|| scene.commit(&renderer)).py_err()?;
            let d = PyDict::new(py);
            d.set_item("rebuilt", r.rebuilt)?;
            d.set_item("refitted", r.refitted)?;
            d.set_item("degraded", r.degraded)?;
            d.set_item("volumes_read", r.volumes_read)?;
            d.set_item("shading", r.shading)?;
            d.set_item("bvh_seconds", r.bvh_time.as_secs_f64())?;
            d.set_item("commit_seconds", r.commit_time.as_secs_f64())?;
            Ok(d)
        })
    }

    /// Renders into a new `(height, width, 4)` array; see `luxon.Scene.render`.
    #[pyo3(signature = (width, height, samples = None, threads = None, dtype = "uint8", progress = None))]
    #[allow(clippy::too_many_arguments)]
    fn _render<'py>(
        &mut self,
        py: Python<'py>,
        width: u32,
        height: u32,
        samples: Option<u32>,
        threads: Option<usize>,
        dtype: &str,
        progress: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        guard(|| {
            let renderer = self.renderer(threads)?;
            crate::render::render(
                py,
                &mut self.scene,
                &renderer,
                crate::render::Request {
                    width,
                    height,
                    samples,
                    dtype,
                    progress,
                },
            )
        })
    }
}

impl PyScene {
    /// The material called `name` (`None`: the default one).
    fn material_id(&self, name: Option<&str>) -> PyResult<Option<MaterialId>> {
        let Some(name) = name else { return Ok(None) };
        let id = self.scene.material(name).ok_or_else(|| {
            PyValueError::new_err(format!(
                "no material named `{name}` in this scene; define it first with \
                 scene.set_material(\"{name}\", ...)"
            ))
        })?;
        Ok(Some(id))
    }

    /// The renderer for `threads` (made once per thread count).
    fn renderer(&mut self, threads: Option<usize>) -> PyResult<Arc<Renderer>> {
        if let Some((_, r)) = self.renderers.iter().find(|(t, _)| *t == threads) {
            return Ok(r.clone());
        }
        let ctx = self.context.get().ctx.clone();
        let r = Arc::new(Renderer::new(&ctx, RendererOptions { threads }).py_err()?);
        self.renderers.push((threads, r.clone()));
        Ok(r)
    }
}
