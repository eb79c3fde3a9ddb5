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

/// One warning as data: what it is about (`K`, a kind with a stable code), the sentence a person reads,
/// the objects it is about and the numbers behind it. The scene's readers ([`SceneWarning`]) and the
/// analysis of a run (`RunWarning`) share it.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning<K> {
    /// What it is about.
    pub kind: K,
    /// The sentence for the report, naming the file or scene.
    pub message: String,
    /// The objects it is about, by the names the file gives them (empty: the whole scene).
    pub objects: Vec<String>,
    /// The numbers it reports, by name (`polygons`, `escape_fraction`), for programs.
    pub numbers: Vec<(&'static str, f64)>,
}

/// One warning about how a scene was read.
pub type SceneWarning = Warning<SceneWarningKind>;

impl<K> Warning<K> {
    /// A warning of `kind` saying `message`, about no object in particular.
    pub fn new(kind: K, message: impl Into<String>) -> Self {
        Warning {
            kind,
            message: message.into(),
            objects: Vec::new(),
            numbers: Vec::new(),
        }
    }

    /// The same warning with numbers for programs.
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

impl<K> std::fmt::Display for Warning<K> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// A quantity in scene units for a sentence: six decimals, or six significant figures in scientific
/// notation when it is too small or too large for them (a scene in metres of a part 1e-6 across).
pub fn quantity_text(x: f64) -> String {
    if x == 0.0 || (1e-3..1e9).contains(&x.abs()) {
        format!("{x:.6}")
    } else {
        format!("{x:.5e}")
    }
}
