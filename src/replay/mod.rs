//! Re-running a recording: the raw sensor topics of an MCAP file fed again through fusion, the
//! altimeter and the navigator — live, through a fresh deployment (`rins replay FILE`), or
//! in-process with the same library code (`rins replay FILE --offline`) — and the navigation output
//! compared with the recorded one, sample for sample. The live feed ([`live`]) is also how the
//! real-data evaluations run their recordings through the running processes
//! (`rins eval quadrotor --mode ahrs --live`).

pub mod compare;
pub mod input;
pub mod live;
pub mod offline;
