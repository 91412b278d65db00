//! How a server runs and stops: until Ctrl-C, SIGTERM or a number of seconds, then cancelled and awaited
//! for at most [`STOP_WAIT`]. Every server of the project (the examples, `nodeset-compiler serve`, the test
//! fixtures, a user's crate) prints `listening on <url>` when ready and `server stopped cleanly` at a clean
//! stop; tests and tools read those two lines.

use std::future::Future;
use std::io::Write;
use std::time::Duration;

use opcua::server::ServerHandle;
use tokio::task::JoinHandle;

use super::ModelServer;

/// How long a cancelled server may take to end.
pub const STOP_WAIT: Duration = Duration::from_secs(10);

/// A future that resolves when the process is asked to stop: SIGINT (Ctrl-C), SIGTERM, or `seconds` after
/// this call when given. The signal handlers are installed by this call, not at the first poll, so a signal
/// sent as soon as the server said it listens is not lost. Must be called inside a tokio runtime.
pub fn stop_requested(seconds: Option<u64>) -> impl Future<Output = ()> + Send + 'static {
    let deadline = seconds.map(|s| tokio::time::Instant::now() + Duration::from_secs(s));
    #[cfg(unix)]
    let signals = {
        use tokio::signal::unix::{signal, SignalKind};
        (signal(SignalKind::interrupt()).ok(), signal(SignalKind::terminate()).ok())
    };
    async move {
        let deadline = async {
            match deadline {
                Some(at) => tokio::time::sleep_until(at).await,
                None => std::future::pending().await,
            }
        };
        #[cfg(unix)]
        let signal = async move {
            let (interrupt, terminate) = signals;
            tokio::select! {
                _ = received(interrupt) => {}
                _ = received(terminate) => {}
            }
        };
        #[cfg(not(unix))]
        let signal = async {
            let _ = tokio::signal::ctrl_c().await;
        };
        tokio::select! {
            _ = signal => {}
            _ = deadline => {}
        }
    }
}

/// Resolves at the signal's first arrival; never when it could not be installed.
#[cfg(unix)]
async fn received(signal: Option<tokio::signal::unix::Signal>) {
    match signal {
        Some(mut s) => {
            s.recv().await;
        }
        None => std::future::pending().await,
    }
}

/// A server serving clients on a task of the tokio runtime ([`ModelServer::start`]).
pub struct RunningServer {
    url: String,
    handle: ServerHandle,
    task: JoinHandle<Result<(), String>>,
}

impl RunningServer {
    /// The URL clients connect to.
    pub fn endpoint_url(&self) -> &str {
        &self.url
    }

    /// Prints `listening on <url>`, serves until `stop` (usually [`stop_requested`], called before the server
    /// started) or `beside` ends (work of the program that runs alongside the server, such as a simulation
    /// loop; `std::future::pending()` when there is none), then stops the server ([`RunningServer::stop`])
    /// and prints `server stopped cleanly`. An error when the server stopped by itself, failed, or did not
    /// end in time.
    pub async fn serve_until(mut self, stop: impl Future<Output = ()>, beside: impl Future<Output = ()>) -> Result<(), String> {
        println!("listening on {}", self.url);
        let _ = std::io::stdout().flush();
        tokio::select! {
            _ = stop => {}
            _ = beside => {}
            why = self.ended() => return Err(why),
        }
        self.stop().await?;
        println!("server stopped cleanly");
        let _ = std::io::stdout().flush();
        Ok(())
    }

    /// Resolves when the server ends by itself (it should not: this is an error of the server or its port),
    /// with how it ended.
    pub async fn ended(&mut self) -> String {
        match (&mut self.task).await {
            Ok(Ok(())) => "the server stopped by itself".to_owned(),
            Ok(Err(e)) => format!("the server stopped by itself: {e}"),
            Err(e) => format!("the server task failed: {e}"),
        }
    }

    /// Cancels the server and waits up to [`STOP_WAIT`] for it to end. Ok when it ended cleanly.
    pub async fn stop(self) -> Result<(), String> {
        self.handle.cancel();
        match tokio::time::timeout(STOP_WAIT, self.task).await {
            Ok(Ok(Ok(()))) => Ok(()),
            Ok(Ok(Err(e))) => Err(format!("the server failed: {e}")),
            Ok(Err(e)) => Err(format!("the server task failed: {e}")),
            Err(_) => Err(format!("the server did not stop within {} s", STOP_WAIT.as_secs())),
        }
    }
}

impl ModelServer {
    /// Starts serving clients on a task of the current tokio runtime.
    pub fn start(self) -> RunningServer {
        let (url, handle) = (self.endpoint_url.clone(), self.handle.clone());
        RunningServer { url, handle, task: tokio::spawn(self.run()) }
    }

    /// Serves until the process is asked to stop ([`stop_requested`] with `seconds`) or `beside` ends:
    /// [`RunningServer::serve_until`].
    pub async fn run_until_stopped(self, seconds: Option<u64>, beside: impl Future<Output = ()>) -> Result<(), String> {
        let stop = stop_requested(seconds);
        self.start().serve_until(stop, beside).await
    }
}
