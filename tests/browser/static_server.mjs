// The browser test's web server: FOLDER's files on 127.0.0.1, over http, or over https with
// the certificate and key given. Prints the origin it serves on stdout once it listens; runs
// until killed.
//   node static_server.mjs FOLDER [CERT.pem KEY.pem]
import { readFileSync } from "node:fs";
import { join, normalize, extname } from "node:path";
import http from "node:http";
import https from "node:https";

const [folder, cert, key] = process.argv.slice(2);
const types = { ".html": "text/html", ".js": "text/javascript" };
const handler = (req, res) => {
  const path = normalize(new URL(req.url, "http://x").pathname).replace(/^\/+/, "") || "index.html";
  try {
    const body = readFileSync(join(folder, path));
    res.writeHead(200, { "content-type": types[extname(path)] ?? "application/octet-stream" });
    res.end(body);
  } catch {
    res.writeHead(404);
    res.end();
  }
};
const server = cert ? https.createServer({ cert: readFileSync(cert), key: readFileSync(key) }, handler) : http.createServer(handler);
server.listen(0, "127.0.0.1", () => console.log(`${cert ? "https" : "http"}://127.0.0.1:${server.address().port}`));
