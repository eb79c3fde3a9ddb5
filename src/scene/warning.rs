//! What a user must know about how a scene was read, as data: each warning has a stable code a program
//! can test, the objects it is about, and a sentence a person can read.

/// What a scene warning is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SceneWarningKind {
    /// Non-planar polygons were split into planar triangles, each a patch.
    NonPlanarSplit,
    /// Triangles of zero area were dropped.
    ZeroAreaTriangles,
    /// Faces of zero area were dropped.
    ZeroAreaFaces,
    /// Faces repeated with the same corners were dropped.
    DuplicateFaces,
    /// Points and lines were skipped: they have no area.
    NoArea,
    /// Textures are not read; materials keep their base colour.
    TexturesIgnored,
    /// A material library was not read; its materials are the default one.
    MaterialLibrary,
    /// Materials named but defined nowhere; their faces get the default material.
    UndefinedMaterials,
    /// Vertex weights of rational curves were ignored.
    VertexWeights,
    /// Materials that look like lights in another convention (`Ka` above 1) but do not emit.
    LightInOtherConvention,
    /// Any other reading problem.
    Other,
}

impl SceneWarningKind {
    /// The stable code of the warning in the JSON report (`non-planar-split`).
    pub fn code(self) -> &'static str {
        match self {
            SceneWarningKind::NonPlanarSplit => "non-planar-split",
            SceneWarningKind::ZeroAreaTriangles => "zero-area-triangles",
            SceneWarningKind::ZeroAreaFaces => "zero-area-faces",
            SceneWarningKind::DuplicateFaces => "duplicate-faces",
            SceneWarningKind::NoArea => "no-area",
            SceneWarningKind::TexturesIgnored => "textures-ignored",
            SceneWarningKind::MaterialLibrary => "material-library",
            SceneWarningKind::UndefinedMaterials => "undefined-materials",
            SceneWarningKind::VertexWeights => "vertex-weights",
            SceneWarningKind::LightInOtherConvention => "light-in-other-convention",
            SceneWarningKind::Other => "scene",
        }
    }
}

/// One warning about how a scene was read.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneWarning {
    /// What it is about.
    pub kind: SceneWarningKind,
    /// The sentence for the report, naming the file.
    pub message: String,
    /// The objects it is about, by the names the file gives them (empty: the whole file).
    pub objects: Vec<String>,
    /// The counts it reports, by name (`polygons`, `triangles`), for programs.
    pub numbers: Vec<(&'static str, f64)>,
}

impl SceneWarning {
    /// A warning of `kind` saying `message`, about no object in particular.
    pub fn new(kind: SceneWarningKind, message: impl Into<String>) -> Self {
        SceneWarning {
            kind,
            message: message.into(),
            objects: Vec::new(),
            numbers: Vec::new(),
        }
    }

    /// The same warning with counts for programs.
    pub fn with_numbers(mut self, numbers: &[(&'static str, f64)]) -> Self {
        self.numbers = numbers.to_vec();
        self
    }

    /// The same warning about these objects.
    pub fn about(mut self, objects: Vec<String>) -> Self {
        self.objects = objects;
        self
    }
}

impl std::fmt::Display for SceneWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
