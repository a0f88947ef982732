//! Raw command-line arguments (clap). Validation into a configuration happens in the commands.

use clap::{Args as ClapArgs, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

/// Correct <inertial> elements for URDF robots, computed from their collision geometry.
#[derive(Debug, Parser)]
#[command(name = "urdf-inertia", version, about, long_about = None)]
pub struct Args {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Write <inertial> for every link with collision geometry (to stdout, -o FILE or -i in place).
    Fill(FillArgs),
    /// Compare each link's existing <inertial> with the one computed from its collision geometry.
    Diff(DiffArgs),
    /// Exit 1 if an <inertial> is invalid, missing, or (with a density source) off; for pre-commit.
    Check(CheckArgs),
    /// Mass properties of one mesh file: volume, mass, COM, inertia, principal axes, health.
    Mesh(MeshArgs),
    /// Expand a xacro file and print the URDF (as the `xacro` tool does).
    Xacro(XacroArgs),
}

#[derive(Debug, Clone, ClapArgs)]
pub struct XacroArgs {
    /// The xacro file (`robot.urdf.xacro`).
    pub file: PathBuf,
    /// xacro arguments, NAME:=VALUE.
    #[arg(value_name = "NAME:=VALUE")]
    pub args: Vec<String>,
    /// Where a ROS package lives, for `$(find NAME)`. Repeatable.
    #[arg(long, value_name = "NAME=DIR")]
    pub package_path: Vec<String>,
    /// Largest input file read: bytes or K/M/G; default 1G, or `URDF_INERTIA_MAX_FILE_SIZE`.
    #[arg(long, value_name = "SIZE")]
    pub max_file_size: Option<String>,
    #[command(flatten)]
    pub diagnostics: DiagnosticArgs,
    /// Bytes read from all input files together in this run: bytes or K/M/G; default 16G, or
    /// `URDF_INERTIA_MAX_TOTAL_READ`.
    #[arg(long, value_name = "SIZE")]
    pub max_total_read: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Default)]
pub enum Format {
    #[default]
    Text,
    Json,
}

/// `--open-mesh`: what an open mesh whose flat caps cannot be trusted becomes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum OpenMesh {
    /// Flat caps over the holes, whatever their bound (the estimate carries it).
    Caps,
    /// The convex hull of the vertices the faces use: an upper bound on the solid.
    Hull,
}

impl OpenMesh {
    /// The library's model for the flag (absent: fail the part, UI108).
    pub fn model(flag: Option<OpenMesh>) -> urdf_inertia::OpenMeshModel {
        use urdf_inertia::OpenMeshModel;
        match flag {
            None => OpenMeshModel::Trusted,
            Some(OpenMesh::Caps) => OpenMeshModel::Caps,
            Some(OpenMesh::Hull) => OpenMeshModel::Hull,
        }
    }
}

/// Where densities come from and where meshes are found: shared by fill, diff and check.
#[derive(Debug, Clone, ClapArgs)]
pub struct SourceArgs {
    /// Density map (TOML): default, `total_mass`, [materials], [links], [meshes].
    #[arg(long, value_name = "FILE", conflicts_with = "density")]
    pub density_map: Option<PathBuf>,
    /// One uniform density for every part, kg/m³.
    #[arg(long, value_name = "RHO")]
    pub density: Option<f64>,
    /// Use each link's existing <mass> as its mass target (the robot was weighed; the inertia is unknown).
    #[arg(long)]
    pub keep_mass: bool,
    /// Where a ROS package lives: `package://NAME/a/b` is DIR/a/b (and `$(find NAME)` in xacro is
    /// DIR). Repeatable.
    #[arg(long, value_name = "NAME=DIR")]
    pub package_path: Vec<String>,
    /// A xacro argument for `.xacro` inputs, NAME:=VALUE. Repeatable.
    #[arg(long = "arg", value_name = "NAME:=VALUE")]
    pub xacro_args: Vec<String>,
    /// Treat every repaired mesh (re-wound, flipped, convex hull) as an error.
    #[arg(long)]
    pub strict: bool,
    /// An open mesh whose flat caps cannot be trusted (bound above 1e-3) fails its link (UI108)
    /// unless a model is chosen: `caps` (used with their bound) or `hull` (the convex hull, an upper
    /// bound).
    #[arg(long, value_enum, value_name = "caps|hull")]
    pub open_mesh: Option<OpenMesh>,
    /// Only these links (glob, repeatable).
    #[arg(long, value_name = "GLOB")]
    pub only: Vec<String>,
    /// Leave these links alone (glob, repeatable).
    #[arg(long, value_name = "GLOB")]
    pub skip: Vec<String>,
    /// Largest input file read (URDF, mesh, density map): bytes or K/M/G; default 1G, or the
    /// `URDF_INERTIA_MAX_FILE_SIZE` environment variable.
    #[arg(long, value_name = "SIZE")]
    pub max_file_size: Option<String>,
    /// Bytes read from all input files together in this run: bytes or K/M/G; default 16G, or
    /// `URDF_INERTIA_MAX_TOTAL_READ`.
    #[arg(long, value_name = "SIZE")]
    pub max_total_read: Option<String>,
    /// Memory the meshes may take: bytes or K/M/G; default the machine's available memory
    /// (`MemAvailable` in /proc/meminfo). A mesh that would need more fails its links, named.
    #[arg(long, value_name = "SIZE")]
    pub max_memory: Option<String>,
    /// Which geometry a link's inertia is computed from, in order: `collision` (default), or
    /// `collision,visual` (a link without collision geometry is computed from its visual geometry,
    /// and marked so in the summary).
    #[arg(long, value_name = "ROLES", default_value = "collision")]
    pub geometry: String,
    /// Accept parts over 10 m across (by default such a part fails its link: a mesh in millimetres
    /// without `scale` weighs 10⁹ times too much).
    #[arg(long)]
    pub allow_large_parts: bool,
    #[command(flatten)]
    pub diagnostics: DiagnosticArgs,
}

/// Which diagnostics are printed, and how (also in `urdf-inertia.toml`).
#[derive(Debug, Clone, ClapArgs)]
pub struct DiagnosticArgs {
    /// Print only errors and problems (no warnings, notes or summary).
    #[arg(short, long)]
    pub quiet: bool,
    /// Silence these codes (`UI102`, or a comma list; repeatable): warnings, notes, or check's
    /// problems (`UI6xx`).
    #[arg(long, value_name = "CODE")]
    pub ignore: Vec<String>,
    /// Make these warnings errors (`UI101`, or a comma list; repeatable): `fill` writes nothing
    /// and exits 2, `diff` and `check` exit 1.
    #[arg(long, value_name = "CODE")]
    pub warn_as_error: Vec<String>,
    /// Repair warnings (UI101, UI102) whose relative error bound is below this are notes
    /// (default 1e-9; 0 keeps them all warnings).
    #[arg(long, value_name = "BOUND")]
    pub note_below: Option<f64>,
    /// Read settings from this file instead of the `urdf-inertia.toml` found by walking up from
    /// the current directory to the repository root.
    #[arg(long, value_name = "FILE", conflicts_with = "no_config")]
    pub config: Option<PathBuf>,
    /// Read no configuration file.
    #[arg(long)]
    pub no_config: bool,
}

// Each bool is a clap flag (`--strict`, `-i`, ...): independent switches, as the command line has them.
#[allow(clippy::struct_excessive_bools)]
#[derive(Debug, Clone, ClapArgs)]
pub struct FillArgs {
    /// The URDF to fill; several with -i (what a pre-commit hook passes: one process, each mesh read
    /// once).
    #[arg(required = true)]
    pub urdf: Vec<PathBuf>,
    #[command(flatten)]
    pub source: SourceArgs,
    /// Write the result to this file instead of stdout (`-` is stdout; devices and FIFOs are written
    /// directly, regular files replaced through a temp file and a rename).
    #[arg(short, long, value_name = "OUT", conflicts_with = "in_place")]
    pub output: Option<PathBuf>,
    /// Rewrite the URDF in place (temp file beside it, then rename).
    #[arg(short, long)]
    pub in_place: bool,
    /// When some links fail, still write the links that worked (the exit status is 2 all the same).
    /// Without it, nothing is written when any link fails.
    #[arg(long)]
    pub keep_going: bool,
    /// Only links whose <inertial> is absent or invalid.
    #[arg(long)]
    pub missing_only: bool,
    /// Digits of the written numbers: `auto` (default: the shortest decimal within each value's error
    /// estimate, so no round-off noise), `full` (every bit: the shortest text that reads back as the
    /// same f64), or N significant digits (3 to 17; the rounded tensor is re-checked, and a link it
    /// cannot keep valid is an error).
    #[arg(long, value_name = "auto|full|N", default_value = "auto")]
    pub digits: urdf_inertia::text::Digits,
    /// Write the principal frame's rpy and a diagonal tensor instead of the tensor in link axes.
    #[arg(long)]
    pub principal: bool,
    /// Summary format on stdout when the URDF is not written there (-o or -i).
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
    /// Also print notes (things that need no action: a mesh welded within tolerance, a zero-size
    /// part); warnings are printed always, and JSON carries both.
    #[arg(short, long)]
    pub verbose: bool,
}

#[derive(Debug, Clone, ClapArgs)]
pub struct DiffArgs {
    /// The URDF to compare.
    pub urdf: PathBuf,
    #[command(flatten)]
    pub source: SourceArgs,
    /// Relative tolerance: a link whose existing mass, COM or inertia is off by more than this makes
    /// the exit status 1 (the same threshold `check` applies).
    #[arg(long, value_name = "REL", default_value_t = 0.05)]
    pub tolerance: f64,
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
    /// Also print notes (things that need no action: a mesh welded within tolerance, a zero-size
    /// part); warnings are printed always, and JSON carries both.
    #[arg(short, long)]
    pub verbose: bool,
}

#[derive(Debug, Clone, ClapArgs)]
pub struct CheckArgs {
    /// URDF files to check.
    #[arg(required = true)]
    pub urdf: Vec<PathBuf>,
    #[command(flatten)]
    pub source: SourceArgs,
    /// Relative tolerance for existing against computed values (with a density source).
    #[arg(long, value_name = "REL", default_value_t = 0.05)]
    pub tolerance: f64,
    /// Also fail on invalid <inertial> of links without collision geometry (dummy roots, sensor
    /// frames), which fill cannot compute; by default they are reported as notes only.
    #[arg(long)]
    pub all_links: bool,
    /// Also print notes (things that need no action: a mesh welded within tolerance, a zero-size
    /// part); warnings are printed always, and JSON carries both.
    #[arg(short, long)]
    pub verbose: bool,
    /// Fail only on problems not recorded in this file (written by --write-baseline; also
    /// `baseline = "FILE"` in urdf-inertia.toml).
    #[arg(long, value_name = "FILE")]
    pub baseline: Option<PathBuf>,
    /// Record today's problems in FILE (one line each: file, link, code, message; sorted) and
    /// exit 0: the repository adopts the check, and later runs with --baseline FILE fail only on
    /// new problems.
    #[arg(long, value_name = "FILE", conflicts_with = "baseline")]
    pub write_baseline: Option<PathBuf>,
    /// With --baseline FILE: record today's problems in it (as --write-baseline FILE).
    #[arg(long, requires = "baseline")]
    pub update: bool,
    /// `json`: the problems as one JSON object on stdout (for CI), instead of a line each.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
}

#[derive(Debug, Clone, ClapArgs)]
pub struct MeshArgs {
    /// STL, OBJ, COLLADA or glTF (.gltf, .glb) file.
    pub file: PathBuf,
    /// Per-axis scale, as in the URDF's <mesh scale>.
    #[arg(long, num_args = 3, value_names = ["SX", "SY", "SZ"], allow_negative_numbers = true)]
    pub scale: Option<Vec<f64>>,
    /// Density, kg/m³ (default 1: the mass equals the volume).
    #[arg(long, conflicts_with = "mass")]
    pub density: Option<f64>,
    /// Total mass, kg (the density follows from the volume).
    #[arg(long)]
    pub mass: Option<f64>,
    /// Treat every repaired mesh as an error.
    #[arg(long)]
    pub strict: bool,
    /// An open mesh whose flat caps cannot be trusted is an error (UI108) unless a model is chosen:
    /// `caps` or `hull` (an upper bound).
    #[arg(long, value_enum, value_name = "caps|hull")]
    pub open_mesh: Option<OpenMesh>,
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
    /// Digits of the numbers: `auto` (default: the shortest decimal within the solid's error
    /// estimate), `full` (every bit: the shortest text that reads back as the same f64), or N
    /// significant digits (3 to 17).
    #[arg(long, value_name = "auto|full|N", default_value = "auto")]
    pub digits: urdf_inertia::text::Digits,
    /// Largest mesh file read: bytes or K/M/G; default 1G, or `URDF_INERTIA_MAX_FILE_SIZE`.
    #[arg(long, value_name = "SIZE")]
    pub max_file_size: Option<String>,
    #[command(flatten)]
    pub diagnostics: DiagnosticArgs,
    /// Bytes read from all input files together in this run: bytes or K/M/G; default 16G, or
    /// `URDF_INERTIA_MAX_TOTAL_READ`.
    #[arg(long, value_name = "SIZE")]
    pub max_total_read: Option<String>,
}
