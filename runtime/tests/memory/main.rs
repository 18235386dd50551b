//! Memory, one test binary with a counting global allocator (`common/counting.rs`): the
//! memory a render (`memory`) and `sdfc mesh` (`mesh_memory`) announce are upper bounds, and
//! the checker's memory stays bounded on inputs built to exhaust it (`check_memory`). The
//! counter sees every thread of the process, so each test measures alone
//! ([`counting::alone`]).

#[path = "../common/counting.rs"]
mod counting;
#[path = "../common/glb.rs"]
mod glb;

mod check_memory;
mod memory;
mod mesh_memory;
