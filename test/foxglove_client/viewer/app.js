// Renders studio-base's App connected through its Foxglove WebSocket data source (the page's
// ?ds=foxglove-websocket&ds.url=... deep link) with one layout: /layout.json (docs/foxglove-layout.json).
// Everything the App would keep in IndexedDB or localStorage is kept in memory: every run starts fresh.
/* global React, ReactDOM, App, FoxgloveWebSocketDataSourceFactory, initI18n */
"use strict";

class MemoryConfiguration {
  constructor() {
    this.values = new Map([["telemetry.telemetryEnabled", false], ["telemetry.crashReportingEnabled", false]]);
    this.listeners = new Map();
  }
  get(key) {
    return this.values.get(key);
  }
  async set(key, value) {
    this.values.set(key, value);
    for (const cb of this.listeners.get(key) ?? []) cb(value);
  }
  addChangeListener(key, cb) {
    if (!this.listeners.has(key)) this.listeners.set(key, new Set());
    this.listeners.get(key).add(cb);
  }
  removeChangeListener(key, cb) {
    this.listeners.get(key)?.delete(cb);
  }
}

class MemoryLayoutStorage {
  constructor(layouts) {
    this.layouts = new Map(layouts.map((l) => [l.id, l]));
  }
  async list() {
    return [...this.layouts.values()];
  }
  async get(_namespace, id) {
    return this.layouts.get(id);
  }
  async put(_namespace, layout) {
    this.layouts.set(layout.id, layout);
    return layout;
  }
  async delete(_namespace, id) {
    this.layouts.delete(id);
  }
  async importLayouts() {}
  async migrateUnnamespacedLayouts() {}
}

async function main() {
  const data = await (await fetch("/layout.json")).json();
  const layout = {
    id: "rbsim",
    name: "rbsim",
    permission: "CREATOR_WRITE",
    baseline: { data, savedAt: new Date().toISOString() },
    working: undefined,
    syncInfo: undefined,
  };
  // The layout is chosen by the page's layoutId=rbsim parameter (the App's own deep link).
  await initI18n();
  ReactDOM.render(
    React.createElement(App, {
      deepLinks: [window.location.href],
      dataSources: [new FoxgloveWebSocketDataSourceFactory()],
      appConfiguration: new MemoryConfiguration(),
      layoutStorage: new MemoryLayoutStorage([layout]),
      extensionLoaders: [],
      enableLaunchPreferenceScreen: false,
      enableGlobalCss: true,
    }),
    document.getElementById("root"),
  );
}

main().catch((err) => {
  document.title = "rbsim viewer: error";
  console.error("rbsim viewer:", err);
});
