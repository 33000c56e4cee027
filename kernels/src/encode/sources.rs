//! The kernel sources, composed per module, and what each entry point binds.

/// WGSL preludes and kernels (composed by [`WgslModule::source`]).
pub mod wgsl {
    pub const PARAMS: &str = include_str!("params.wgsl");
    pub const TOPOLOGY: &str = include_str!("topology.wgsl");
    pub const QUADRIC: &str = include_str!("quadric.wgsl");
    pub const QUADRIC_INIT: &str = include_str!("quadric_init.wgsl");
    pub const BEST_EDGE: &str = include_str!("best_edge.wgsl");
    pub const SELECT: &str = include_str!("select.wgsl");
    pub const UPDATE: &str = include_str!("update.wgsl");
}

/// OpenCL C sources, concatenated into one program by [`opencl_program`].
pub mod opencl {
    pub const COMMON: &str = include_str!("encode_common.cl");
    pub const QUADRIC_INIT: &str = include_str!("quadric_init.cl");
    pub const BEST_EDGE: &str = include_str!("best_edge.cl");
    pub const SELECT: &str = include_str!("select.cl");
    pub const UPDATE: &str = include_str!("update.cl");
}

/// The whole OpenCL program.
pub fn opencl_program() -> String {
    use opencl::*;
    [COMMON, QUADRIC_INIT, BEST_EDGE, SELECT, UPDATE].concat()
}

/// One WGSL shader module (WGSL has no includes: preludes are prepended).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WgslModule {
    QuadricInit,
    BestEdge,
    Select,
    Update,
}

impl WgslModule {
    pub const ALL: [WgslModule; 4] = [
        WgslModule::QuadricInit,
        WgslModule::BestEdge,
        WgslModule::Select,
        WgslModule::Update,
    ];

    pub fn name(self) -> &'static str {
        match self {
            WgslModule::QuadricInit => "quadric_init.wgsl",
            WgslModule::BestEdge => "best_edge.wgsl",
            WgslModule::Select => "select.wgsl",
            WgslModule::Update => "update.wgsl",
        }
    }

    pub fn source(self) -> String {
        use wgsl::*;
        let parts: &[&str] = match self {
            WgslModule::QuadricInit => &[PARAMS, TOPOLOGY, QUADRIC_INIT],
            WgslModule::BestEdge => &[PARAMS, TOPOLOGY, QUADRIC, BEST_EDGE],
            WgslModule::Select => &[PARAMS, TOPOLOGY, SELECT],
            WgslModule::Update => &[PARAMS, UPDATE],
        };
        parts.join("\n")
    }
}

/// Buffers the kernels bind; the WGSL binding number is the discriminant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Slot {
    Params = 0,
    Corners = 1,
    CornerOf = 2,
    Vertices = 3,
    Quadrics = 4,
    Best = 5,
    Blocked = 6,
    Keys = 7,
    /// Whichever vertex list the dispatch walks (dirty or live).
    List = 8,
    Winners = 9,
    Counter = 10,
    Updates = 11,
    /// The live vertices' request errors (`live_errors`).
    Errors = 12,
}

/// One compute entry point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    QuadricInit,
    BestEdge,
    Admit,
    LocalMin,
    Block,
    LiveErrors,
    UpdateTriangles,
    UpdateVertices,
}

impl Kernel {
    pub const ALL: [Kernel; 8] = [
        Kernel::QuadricInit,
        Kernel::BestEdge,
        Kernel::Admit,
        Kernel::LocalMin,
        Kernel::Block,
        Kernel::LiveErrors,
        Kernel::UpdateTriangles,
        Kernel::UpdateVertices,
    ];

    /// Entry point name, the same in WGSL and OpenCL C.
    pub fn entry(self) -> &'static str {
        match self {
            Kernel::QuadricInit => "quadric_init",
            Kernel::BestEdge => "best_edge",
            Kernel::Admit => "admit",
            Kernel::LocalMin => "local_min",
            Kernel::Block => "block",
            Kernel::LiveErrors => "live_errors",
            Kernel::UpdateTriangles => "update_triangles",
            Kernel::UpdateVertices => "update_vertices",
        }
    }

    pub fn module(self) -> WgslModule {
        match self {
            Kernel::QuadricInit => WgslModule::QuadricInit,
            Kernel::BestEdge => WgslModule::BestEdge,
            Kernel::Admit | Kernel::LocalMin | Kernel::Block | Kernel::LiveErrors => {
                WgslModule::Select
            }
            Kernel::UpdateTriangles | Kernel::UpdateVertices => WgslModule::Update,
        }
    }

    /// The buffers the entry point uses, in binding order: WGSL bindings
    /// (the pipeline layout derived from the shader has exactly these) and
    /// the OpenCL kernel's arguments, in this order.
    pub fn slots(self) -> &'static [Slot] {
        use Slot::*;
        match self {
            Kernel::QuadricInit => &[Params, Corners, CornerOf, Vertices, Quadrics],
            Kernel::BestEdge => &[
                Params, Corners, CornerOf, Vertices, Quadrics, Best, Blocked, List,
            ],
            Kernel::Admit => &[Params, Best, Blocked, Keys, List],
            Kernel::LocalMin => &[
                Params, Corners, CornerOf, Best, Keys, List, Winners, Counter,
            ],
            Kernel::Block => &[Params, Corners, CornerOf, Blocked, Winners],
            Kernel::LiveErrors => &[Params, Best, List, Errors],
            Kernel::UpdateTriangles => &[Params, Corners, Updates],
            Kernel::UpdateVertices => &[Params, CornerOf, Vertices, Quadrics, Updates],
        }
    }
}
