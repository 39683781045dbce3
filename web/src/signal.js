// A named event with listeners: the editor's only way to tell panels that state changed.
export class Signal {
  constructor() {
    this.listeners = new Set();
  }

  add(fn) {
    this.listeners.add(fn);
    return () => this.listeners.delete(fn);
  }

  dispatch(...args) {
    for (const fn of [...this.listeners]) fn(...args);
  }
}
